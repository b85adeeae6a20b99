//! The self-contained HTML report: one file holding a skinned glTF binary (base64), the
//! skinning report JSON and the project's own WebGL2 viewer (`viewer/`), so that it opens
//! from `file://` with no network request.
//!
//! The viewer reads these report keys, each optional: `decomposition.joints[]` (`name`,
//! `status`, `reason`, `perimeter`, `diameter`, `overlap…`; the cut as `curve`: a closed list
//! of `[x, y, z]` in the glb's bind space, or as `point`, `normal` and `diameter`, drawn as a
//! circle), `decomposition.regions[]` (`joint`, `joints`: names; a vertex takes the region of
//! its dominant joint), `decomposition.vertex_regions` (a region index per vertex of the
//! skinned mesh, glb order; overrides the dominant joint), `pieces.treatments` (names of
//! treatments) with `pieces.vertex_treatments` (an index into them per vertex of the
//! skinned mesh, glb order; with both, the view offers the colour mode "pieces", a fixed
//! colour per treatment name), `timings_ms` (stage → ms), `warnings` (strings), `counts`
//! and any other top-level scalar.

use atlas_skin_io::{IoError, OutputPlan};
use base64::Engine;
use std::path::Path;
use thiserror::Error;

/// Why the page could not be made or written.
#[derive(Debug, Error)]
pub enum HtmlError {
    /// The model is not a glTF 2.0 binary.
    #[error("{0}")]
    Glb(String),
    /// The viewer template is broken (a marker unclosed or unknown).
    #[error("{0}")]
    Template(String),
    #[error("serialising the report JSON")]
    Report(#[source] serde_json::Error),
    #[error(transparent)]
    Write(#[from] IoError),
}

/// The page around the model; `@@NAME@@` markers are filled by [`fill_template`].
const TEMPLATE: &str = include_str!("../viewer/viewer.html");
/// The viewer's scripts, joined in this order inside one function of the page's script; the
/// last one starts the viewer.
const VIEWER_JS: [&str; 10] = [
    include_str!("../viewer/math.js"),
    include_str!("../viewer/gltf.js"),
    include_str!("../viewer/pose.js"),
    include_str!("../viewer/report.js"),
    include_str!("../viewer/gpu.js"),
    include_str!("../viewer/draw.js"),
    include_str!("../viewer/camera.js"),
    include_str!("../viewer/controls.js"),
    include_str!("../viewer/pointer.js"),
    include_str!("../viewer/viewer.js"),
];
const GLSL_SKINNING: &str = include_str!("../viewer/skinning.glsl");
const GLSL_MESH_VERT: &str = include_str!("../viewer/mesh.vert");
const GLSL_MESH_FRAG: &str = include_str!("../viewer/mesh.frag");
const GLSL_LINE_VERT: &str = include_str!("../viewer/line.vert");
const GLSL_LINE_FRAG: &str = include_str!("../viewer/line.frag");

/// Magic of a glTF binary: ASCII "glTF" read as a little-endian u32 (glTF 2.0 §4.4.2).
const GLB_MAGIC: u32 = 0x4654_6c67;

/// Writes `out` through `plan`: an HTML page showing `glb_bytes` (a glTF 2.0 binary,
/// skinned or not) with the optional skinning report (the JSON of `atlas-skin skin
/// --report`; every key is optional) in its side panel. `out` also gives the page's title.
pub fn write_html(
    glb_bytes: &[u8],
    report_json: Option<&serde_json::Value>,
    out: &Path,
    plan: &OutputPlan,
) -> Result<(), HtmlError> {
    check_glb_header(glb_bytes)?;
    let title = out
        .file_stem()
        .map(|stem| stem.to_string_lossy().into_owned())
        .unwrap_or_else(|| "report".to_owned());
    let report = match report_json {
        Some(value) => script_safe_json(&with_viewer_precision(value))?,
        None => String::new(),
    };
    let glb_base64 = base64::engine::general_purpose::STANDARD.encode(glb_bytes);
    let page = fill_template(
        TEMPLATE,
        &[
            ("TITLE", &escape_html(&title)),
            ("GLB_BASE64", &glb_base64),
            ("REPORT_JSON", &report),
            ("GLSL_SKINNING", GLSL_SKINNING),
            ("GLSL_MESH_VERT", GLSL_MESH_VERT),
            ("GLSL_MESH_FRAG", GLSL_MESH_FRAG),
            ("GLSL_LINE_VERT", GLSL_LINE_VERT),
            ("GLSL_LINE_FRAG", GLSL_LINE_FRAG),
            ("VIEWER_JS", &viewer_script()),
        ],
    )?;
    Ok(plan.write(out, page.as_bytes())?)
}

/// The viewer's scripts joined in order, without their whole-line `//` comments: the sources'
/// documentation stays out of every report. No line of the scripts lies inside a multi-line
/// string, where such a line would be text (a test checks their backticks).
fn viewer_script() -> String {
    let mut script = String::new();
    for line in VIEWER_JS.iter().flat_map(|source| source.lines()) {
        if !is_comment_line(line) {
            script.push_str(line);
            script.push('\n');
        }
    }
    script
}

fn is_comment_line(line: &str) -> bool {
    line.trim_start().starts_with("//")
}

/// Checks the 12-byte GLB header: magic, version 2 and a declared length equal to the data's.
fn check_glb_header(bytes: &[u8]) -> Result<(), HtmlError> {
    let word = |at: usize| {
        bytes
            .get(at..at + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    match (word(0), word(4), word(8)) {
        (Some(GLB_MAGIC), Some(2), Some(length)) if length as usize == bytes.len() => Ok(()),
        (Some(GLB_MAGIC), Some(2), Some(length)) => Err(HtmlError::Glb(format!(
            "the glTF binary declares {length} bytes but has {}",
            bytes.len()
        ))),
        (Some(GLB_MAGIC), Some(version), _) => Err(HtmlError::Glb(format!(
            "glTF binary version {version} is not supported (only 2)"
        ))),
        _ => Err(HtmlError::Glb(
            "not a glTF binary (.glb): the file does not start with \"glTF\"".into(),
        )),
    }
}

/// Replaces every `@@NAME@@` marker of `template` by its value in one pass, so text inside
/// the values (model data, report strings) is never taken for a marker. An unknown or
/// unclosed marker is an error.
fn fill_template(template: &str, values: &[(&str, &str)]) -> Result<String, HtmlError> {
    let mut page =
        String::with_capacity(template.len() + values.iter().map(|(_, v)| v.len()).sum::<usize>());
    let mut rest = template;
    while let Some(start) = rest.find("@@") {
        page.push_str(&rest[..start]);
        let after = &rest[start + 2..];
        let end = after.find("@@").ok_or_else(|| {
            HtmlError::Template(format!(
                "unclosed marker in the viewer template near {:?}",
                &after[..after.len().min(20)]
            ))
        })?;
        let name = &after[..end];
        let (_, value) = values.iter().find(|(key, _)| *key == name).ok_or_else(|| {
            HtmlError::Template(format!(
                "the viewer template has an unknown marker @@{name}@@"
            ))
        })?;
        page.push_str(value);
        rest = &after[end + 2..];
    }
    page.push_str(rest);
    Ok(page)
}

/// A copy of `value` whose non-integer numbers keep 7 significant digits: the viewer works
/// in f32 (24-bit mantissa, about 7.2 digits), and the report's curves and vectors shrink to
/// less than half their full f64 text.
fn with_viewer_precision(value: &serde_json::Value) -> serde_json::Value {
    use serde_json::Value;
    match value {
        Value::Number(n) if !(n.is_i64() || n.is_u64()) => n
            .as_f64()
            .and_then(|x| format!("{x:.6e}").parse::<f64>().ok())
            .and_then(serde_json::Number::from_f64)
            .map_or_else(|| value.clone(), Value::Number),
        Value::Array(items) => Value::Array(items.iter().map(with_viewer_precision).collect()),
        Value::Object(map) => Value::Object(
            map.iter()
                .map(|(key, item)| (key.clone(), with_viewer_precision(item)))
                .collect(),
        ),
        _ => value.clone(),
    }
}

/// JSON that can sit inside a `<script>` element: `<` (which only occurs inside JSON
/// strings) becomes the escape `\u003c`, so no `</script>` or `<!--` can end the element.
fn script_safe_json(value: &serde_json::Value) -> Result<String, HtmlError> {
    let text = serde_json::to_string(value).map_err(HtmlError::Report)?;
    Ok(text.replace('<', "\\u003c"))
}

/// Text for HTML element content and attribute values.
fn escape_html(text: &str) -> String {
    let mut escaped = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => escaped.push_str("&amp;"),
            '<' => escaped.push_str("&lt;"),
            '>' => escaped.push_str("&gt;"),
            '"' => escaped.push_str("&quot;"),
            '\'' => escaped.push_str("&#39;"),
            _ => escaped.push(c),
        }
    }
    escaped
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A minimal valid glTF binary: header and an empty-scene JSON chunk.
    fn tiny_glb() -> Vec<u8> {
        let json = br#"{"asset":{"version":"2.0"}}    "#;
        let mut bytes = Vec::new();
        bytes.extend_from_slice(&GLB_MAGIC.to_le_bytes());
        bytes.extend_from_slice(&2u32.to_le_bytes());
        bytes.extend_from_slice(&((12 + 8 + json.len()) as u32).to_le_bytes());
        bytes.extend_from_slice(&(json.len() as u32).to_le_bytes());
        bytes.extend_from_slice(&0x4E4F_534Au32.to_le_bytes());
        bytes.extend_from_slice(json);
        bytes
    }

    #[test]
    fn template_markers_are_filled_once() {
        let page = fill_template("a @@X@@ b @@Y@@", &[("X", "@@Y@@"), ("Y", "2")]).unwrap();
        assert_eq!(page, "a @@Y@@ b 2");
    }

    #[test]
    fn unknown_or_unclosed_markers_are_errors() {
        assert!(fill_template("@@Z@@", &[("X", "1")]).is_err());
        assert!(fill_template("a @@X", &[("X", "1")]).is_err());
    }

    #[test]
    fn viewer_template_has_every_marker_filled() {
        let dir = std::env::temp_dir().join(format!("atlas-skin-html-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let out = dir.join("tiny.html");
        let plan = OutputPlan::new([], [out.as_path()]).unwrap();
        write_html(&tiny_glb(), None, &out, &plan).unwrap();
        let page = std::fs::read_to_string(&out).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
        assert!(!page.contains("@@"), "a marker was left in the page");
        assert!(page.contains("<title>atlas-skin report: tiny</title>"));
    }

    #[test]
    fn embedded_sources_cannot_close_their_script_element() {
        for source in VIEWER_JS.into_iter().chain([
            GLSL_SKINNING,
            GLSL_MESH_VERT,
            GLSL_MESH_FRAG,
            GLSL_LINE_VERT,
            GLSL_LINE_FRAG,
        ]) {
            assert!(!source.to_ascii_lowercase().contains("</script"));
            assert!(
                !source.contains("@@"),
                "a source contains the template marker"
            );
        }
    }

    #[test]
    fn viewer_script_leaves_out_comment_lines_only() {
        // A template literal spanning lines would show as a code line with an odd number of
        // backticks: then a `//` line could be its text, not a comment.
        for source in VIEWER_JS {
            for line in source.lines().filter(|line| !is_comment_line(line)) {
                assert_eq!(
                    line.matches('`').count() % 2,
                    0,
                    "multi-line string at {line:?}"
                );
            }
        }
        let script = viewer_script();
        assert!(!script.lines().any(is_comment_line));
        let sources: usize = VIEWER_JS.iter().map(|source| source.len()).sum();
        assert!(
            script.len() < sources * 9 / 10,
            "few comment lines were left out"
        );
        for code in [
            "const mat4 = {",
            "function start() {",
            "  start();",
            "const POSE_DEAD_ZONE = 8;",
        ] {
            assert!(script.contains(code), "{code:?} is missing");
        }
    }

    #[test]
    fn report_strings_cannot_close_the_script_element() {
        let value = serde_json::json!({ "warnings": ["</script><script>alert(1)</script>"] });
        let text = script_safe_json(&value).unwrap();
        assert!(!text.contains('<'));
        let back: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(back, value);
    }

    #[test]
    fn report_numbers_keep_seven_significant_digits() {
        let value = serde_json::json!({
            "curve": [[1.1198194281633318, -0.000123456789, 12345678.9]],
            "count": 16000,
            "name": "spine",
        });
        let compact = with_viewer_precision(&value);
        assert_eq!(
            compact,
            serde_json::json!({
                "curve": [[1.119819, -0.0001234568, 12345680.0]],
                "count": 16000,
                "name": "spine",
            })
        );
    }

    #[test]
    fn titles_are_escaped() {
        assert_eq!(
            escape_html(r#"<a href="x">&'"#),
            "&lt;a href=&quot;x&quot;&gt;&amp;&#39;"
        );
    }

    #[test]
    fn bad_glb_headers_are_rejected() {
        let glb = tiny_glb();
        assert!(check_glb_header(&glb).is_ok());
        assert!(check_glb_header(b"{\"asset\":{}}").is_err());
        assert!(check_glb_header(&glb[..glb.len() - 1]).is_err());
        let mut version_1 = glb.clone();
        version_1[4] = 1;
        assert!(check_glb_header(&version_1).is_err());
        assert!(check_glb_header(&[]).is_err());
    }
}

//! `atlas-skin report`: what the HTML file holds and how bad input is refused.

mod support;

use atlas_skin_corpus::{motion_path, CESIUMMAN};
use base64::Engine;
use std::path::{Path, PathBuf};
use std::process::Output;
use support::{atlas_skin, out_dir};

fn cesiumman() -> PathBuf {
    CESIUMMAN.input_path()
}

/// A fresh scratch folder for one test.
fn scratch(name: &str) -> PathBuf {
    out_dir(&format!("report_cli/{name}"))
}

/// `atlas-skin report ARGS...`.
fn report(args: &[&Path]) -> Output {
    let mut all = vec![Path::new("report")];
    all.extend_from_slice(args);
    atlas_skin(&all)
}

/// `atlas-skin report CesiumMan.glb FLAG FILE -o OUT`.
fn report_cesiumman_with(flag: &str, file: &Path, out: &Path) -> Output {
    report(&[&cesiumman(), Path::new(flag), file, Path::new("-o"), out])
}

/// The text content of the `<script ... id="ID">` element of `page`.
fn script_content<'a>(page: &'a str, id: &str) -> &'a str {
    let open = format!("id=\"{id}\">");
    let start = page
        .find(&open)
        .unwrap_or_else(|| panic!("no element {id}"))
        + open.len();
    let end = start + page[start..].find("</script>").unwrap();
    &page[start..end]
}

#[test]
fn the_page_embeds_the_model_and_the_report_intact() {
    let dir = scratch("embeds");
    let report_json = serde_json::json!({
        "decomposition": { "joints": [{ "name": "</script><script>alert(1)</script>", "status": "cut" }] },
        "warnings": ["<!-- not a comment -->"],
    });
    let report_path = dir.join("r.json");
    std::fs::write(&report_path, report_json.to_string()).unwrap();
    let out = dir.join("cesiumman.html");
    let output = report_cesiumman_with("--report", &report_path, &out);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );

    let page = std::fs::read_to_string(&out).unwrap();
    let glb = base64::engine::general_purpose::STANDARD
        .decode(script_content(&page, "model-glb"))
        .unwrap();
    assert_eq!(glb, std::fs::read(cesiumman()).unwrap());
    let embedded: serde_json::Value =
        serde_json::from_str(script_content(&page, "report-json")).unwrap();
    assert_eq!(embedded, report_json);
    assert_eq!(
        page.matches("</script>").count(),
        8,
        "one per script element"
    );
    // Nothing is fetched: no URL of any scheme other than the page's own text.
    for scheme in ["http:", "https:", "//cdn", "src="] {
        assert!(!page.contains(scheme), "the page refers to {scheme}");
    }
}

#[test]
fn a_file_that_is_not_a_glb_is_refused_and_nothing_is_written() {
    let dir = scratch("not_glb");
    let input = dir.join("mesh.glb");
    std::fs::write(&input, "{\"asset\":{\"version\":\"2.0\"}}").unwrap();
    let out = dir.join("r.html");
    let output = report(&[&input, Path::new("-o"), &out]);
    assert!(!output.status.success());
    assert!(String::from_utf8_lossy(&output.stderr).contains("not a glTF binary"));
    assert!(!out.exists());
    assert_eq!(
        std::fs::read_dir(&dir).unwrap().count(),
        1,
        "a temporary file was left"
    );
}

#[test]
fn an_invalid_report_json_is_refused() {
    let dir = scratch("bad_json");
    let report_path = dir.join("r.json");
    std::fs::write(&report_path, "{ not json").unwrap();
    let out = dir.join("r.html");
    let output = report_cesiumman_with("--report", &report_path, &out);
    assert!(!output.status.success());
    assert!(String::from_utf8_lossy(&output.stderr).contains("is not valid JSON"));
    assert!(!out.exists());
}

#[test]
fn the_report_never_replaces_its_input() {
    let dir = scratch("overwrite");
    let input = dir.join("model.glb");
    std::fs::copy(cesiumman(), &input).unwrap();
    let output = report(&[&input, Path::new("-o"), &dir.join("./model.glb")]);
    assert!(!output.status.success());
    assert!(
        String::from_utf8_lossy(&output.stderr).contains("refusing to write over the input file")
    );
    assert_eq!(
        std::fs::read(&input).unwrap(),
        std::fs::read(cesiumman()).unwrap()
    );
}

#[test]
fn a_motion_whose_joints_match_none_of_the_character_is_refused() {
    let dir = scratch("bvh_mismatch");
    let walk = motion_path("walk.bvh");
    let out = dir.join("r.html");
    // CesiumMan's joints carry no names, so no BVH joint maps onto them.
    let output = report_cesiumman_with("--bvh", &walk, &out);
    assert!(!output.status.success());
    assert!(String::from_utf8_lossy(&output.stderr).contains("putting the motion"));
    assert!(!out.exists());
}

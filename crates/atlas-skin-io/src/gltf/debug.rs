//! An unskinned `.glb` for looking at intermediate results: a mesh coloured per vertex
//! (regions, weights) and line segments (cut curves, bones).

use super::builder::{GlbBuilder, ARRAY_BUFFER};
use crate::IoError;
use glam::Vec3;
use serde_json::{json, Map};
use std::path::Path;

/// glTF primitive modes used here.
const LINES: u32 = 1;
const TRIANGLES: u32 = 4;

/// A glTF binary with a TRIANGLES primitive and a LINES primitive (`out`, where it will
/// be written, only names it in errors).
///
/// - `positions`: #V vertex positions; `triangles`: #F index triples into them.
/// - `vertex_colors`: #V linear RGBA colours in [0, 1] (COLOR_0), or empty for none.
/// - `lines`: #L segments, drawn in `line_color` (RGBA in [0, 1]).
///
/// Either part may be empty, not both.
///
/// # Errors
/// [`IoError::Invalid`] when there is nothing to draw, a triangle index is out of range,
/// the colour count differs from the vertex count, or a value is not finite.
pub fn debug_glb(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    vertex_colors: &[[f32; 4]],
    lines: &[[Vec3; 2]],
    line_color: [f32; 4],
    out: &Path,
) -> Result<Vec<u8>, IoError> {
    let invalid = |message: String| IoError::invalid(out, message);
    if triangles.is_empty() && lines.is_empty() {
        return Err(invalid("nothing to write: no triangle and no line".into()));
    }
    if let Some(t) = triangles
        .iter()
        .flatten()
        .find(|&&v| v as usize >= positions.len())
    {
        return Err(invalid(format!(
            "triangle index {t} is out of range of {} positions",
            positions.len()
        )));
    }
    if !vertex_colors.is_empty() && vertex_colors.len() != positions.len() {
        return Err(invalid(format!(
            "{} vertex colours for {} positions",
            vertex_colors.len(),
            positions.len()
        )));
    }
    let finite = positions.iter().all(|p| p.is_finite())
        && lines.iter().flatten().all(|p| p.is_finite())
        && vertex_colors
            .iter()
            .chain([&line_color])
            .flatten()
            .all(|c| c.is_finite());
    if !finite {
        return Err(invalid("a position or colour is not finite".into()));
    }

    let mut builder = GlbBuilder::new(Map::new());
    builder.json_mut().insert(
        "asset".into(),
        json!({"version": "2.0", "generator": "atlas-skin debug"}),
    );
    let mut primitives = Vec::new();
    if !triangles.is_empty() {
        let (position, indices) = builder.push_triangle_mesh(positions, triangles);
        let mut attributes = json!({"POSITION": position});
        if !vertex_colors.is_empty() {
            let colors: Vec<f32> = vertex_colors.iter().flatten().copied().collect();
            attributes["COLOR_0"] =
                json!(builder.push_f32_accessor(&colors, "VEC4", false, Some(ARRAY_BUFFER)));
        }
        primitives.push(json!({"attributes": attributes, "indices": indices, "mode": TRIANGLES}));
    }
    if !lines.is_empty() {
        let flat: Vec<f32> = lines.iter().flatten().flat_map(|p| p.to_array()).collect();
        let position = builder.push_f32_accessor(&flat, "VEC3", true, Some(ARRAY_BUFFER));
        let colors: Vec<f32> = std::iter::repeat_n(line_color, 2 * lines.len())
            .flatten()
            .collect();
        let color = builder.push_f32_accessor(&colors, "VEC4", false, Some(ARRAY_BUFFER));
        primitives.push(json!({
            "attributes": {"POSITION": position, "COLOR_0": color},
            "mode": LINES,
        }));
    }
    builder.push_item("meshes", json!({"name": "debug", "primitives": primitives}));
    builder.push_item("nodes", json!({"name": "debug", "mesh": 0}));
    builder.push_item("scenes", json!({"nodes": [0]}));
    builder.json_mut().insert("scene".into(), json!(0));
    Ok(builder.finish())
}

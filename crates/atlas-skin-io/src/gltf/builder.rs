//! Building a single-buffer `.glb`: a JSON document plus one BIN chunk that grows as
//! bufferViews and accessors are appended.

use super::accessor::ComponentType;
use super::container::glb_bytes;
use serde_json::{json, Map, Value};
use std::ops::Range;

/// `bufferView.target` of vertex attributes.
pub(crate) const ARRAY_BUFFER: u32 = 34962;
/// `bufferView.target` of vertex indices.
pub(crate) const ELEMENT_ARRAY_BUFFER: u32 = 34963;

/// A glTF document being written with its binary buffer (buffer 0 of the output).
pub(crate) struct GlbBuilder {
    json: Map<String, Value>,
    bin: Vec<u8>,
}

impl GlbBuilder {
    /// Starts from the top-level object `json` (its `buffers` are replaced on
    /// [`GlbBuilder::finish`]).
    pub fn new(json: Map<String, Value>) -> Self {
        Self::with_capacity(json, 0)
    }

    /// As [`GlbBuilder::new`], with room for `bytes` of binary data (and the file's
    /// header and JSON, which [`GlbBuilder::finish`] puts in front of it) before the buffer
    /// grows: growing copies it, and memory reserved but never written costs no page.
    pub fn with_capacity(json: Map<String, Value>, bytes: usize) -> Self {
        Self {
            json,
            bin: Vec::with_capacity(bytes),
        }
    }

    /// The document's top-level object.
    pub fn json_mut(&mut self) -> &mut Map<String, Value> {
        &mut self.json
    }

    /// Appends `item` to the top-level array `key` (created when missing) and returns its
    /// index.
    pub fn push_item(&mut self, key: &str, item: Value) -> usize {
        let entry = self
            .json
            .entry(key)
            .or_insert_with(|| Value::Array(Vec::new()));
        match entry {
            Value::Array(items) => {
                items.push(item);
                items.len() - 1
            }
            other => {
                *other = Value::Array(vec![item]);
                0
            }
        }
    }

    /// Appends `bytes` to the binary buffer at an offset congruent to `phase` modulo 4
    /// (0 for new data; the old offset's phase when copying a view, so the accessors inside
    /// keep their alignment) and returns that offset.
    pub fn append_bytes(&mut self, bytes: &[u8], phase: usize) -> usize {
        let offset = self.bin.len().next_multiple_of(4) + phase % 4;
        self.bin.resize(offset, 0);
        self.bin.extend_from_slice(bytes);
        offset
    }

    /// Appends `bytes` as a new bufferView (4-byte aligned) and returns its index.
    pub fn push_view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        let offset = self.append_bytes(bytes, 0);
        let mut view = json!({"buffer": 0, "byteOffset": offset, "byteLength": bytes.len()});
        if let Some(target) = target {
            view["target"] = json!(target);
        }
        self.push_item("bufferViews", view)
    }

    /// Appends an accessor over the whole of bufferView `view`.
    fn push_accessor(
        &mut self,
        view: usize,
        component: ComponentType,
        type_name: &str,
        count: usize,
        bounds: Option<(Vec<f32>, Vec<f32>)>,
    ) -> usize {
        let mut accessor = json!({
            "bufferView": view,
            "componentType": component.code(),
            "count": count,
            "type": type_name,
        });
        if let Some((min, max)) = bounds {
            accessor["min"] = json!(min);
            accessor["max"] = json!(max);
        }
        self.push_item("accessors", accessor)
    }

    /// Appends float `values` (flattened elements of `type_name`) as a view and an accessor,
    /// with per-component `min`/`max` when `with_bounds`.
    pub fn push_f32_accessor(
        &mut self,
        values: &[f32],
        type_name: &str,
        with_bounds: bool,
        target: Option<u32>,
    ) -> usize {
        let components = components_of(type_name);
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.push_view(&bytes, target);
        let bounds = with_bounds.then(|| component_bounds(values, components));
        self.push_accessor(
            view,
            ComponentType::F32,
            type_name,
            values.len() / components,
            bounds,
        )
    }

    /// Appends mesh geometry: `positions` as a VEC3 float accessor with bounds and
    /// `triangles` as an index accessor of the smallest allowed type. Returns (position
    /// accessor, index accessor).
    pub fn push_triangle_mesh(
        &mut self,
        positions: &[glam::Vec3],
        triangles: &[[u32; 3]],
    ) -> (usize, usize) {
        let flat: Vec<f32> = positions.iter().flat_map(|p| p.to_array()).collect();
        let position = self.push_f32_accessor(&flat, "VEC3", true, Some(ARRAY_BUFFER));
        (position, self.push_indices(triangles, positions.len()))
    }

    /// Appends `triangles` over `vertex_count` vertices as an index accessor of the smallest
    /// allowed type and returns it.
    pub fn push_indices(&mut self, triangles: &[[u32; 3]], vertex_count: usize) -> usize {
        let flat_indices: Vec<u32> = triangles.iter().flatten().copied().collect();
        self.push_uint_accessor(
            &flat_indices,
            index_component(vertex_count),
            "SCALAR",
            Some(ELEMENT_ARRAY_BUFFER),
        )
    }

    /// Appends unsigned integer `values` (flattened elements of `type_name`) stored as
    /// `component` (U8, U16 or U32; every value must fit).
    pub fn push_uint_accessor(
        &mut self,
        values: &[u32],
        component: ComponentType,
        type_name: &str,
        target: Option<u32>,
    ) -> usize {
        let bytes: Vec<u8> = match component {
            ComponentType::U8 => values.iter().map(|&v| v as u8).collect(),
            ComponentType::U16 => values
                .iter()
                .flat_map(|&v| (v as u16).to_le_bytes())
                .collect(),
            _ => values.iter().flat_map(|v| v.to_le_bytes()).collect(),
        };
        debug_assert!(values
            .iter()
            .all(|&v| (v as u64) < 1u64 << (8 * component.size())));
        let view = self.push_view(&bytes, target);
        let count = values.len() / components_of(type_name);
        self.push_accessor(view, component, type_name, count, None)
    }

    /// The document's top-level object and the binary buffer, for a pass that rebuilds
    /// both (see [`GlbBuilder::from_parts`]).
    pub fn into_parts(self) -> (Map<String, Value>, Vec<u8>) {
        (self.json, self.bin)
    }

    /// A builder continuing from `json` and its binary buffer `bin`.
    pub fn from_parts(json: Map<String, Value>, bin: Vec<u8>) -> Self {
        Self { json, bin }
    }

    /// The finished `.glb`: one buffer holding everything appended.
    pub fn finish(mut self) -> Vec<u8> {
        if self.bin.is_empty() {
            self.json.remove("buffers");
        } else {
            self.json
                .insert("buffers".into(), json!([{"byteLength": self.bin.len()}]));
        }
        glb_bytes(&Value::Object(self.json), self.bin)
    }
}

/// `bin` reduced to the byte `ranges`, in order, each placed as
/// [`GlbBuilder::append_bytes`] places it (at the next multiple of 4 plus the phase of its
/// old start, the gap zeroed); returns the bytes and the new offset of every range.
///
/// The bytes are moved within `bin` when no range is written over bytes of a later range
/// still to be moved (always the case for the views of a rewritten document: each lies
/// after the previous one): no second buffer. Otherwise they are copied into a new one
/// ([`keep_ranges_by_copy`], the reference).
pub(crate) fn keep_ranges(mut bin: Vec<u8>, ranges: &[Range<usize>]) -> (Vec<u8>, Vec<usize>) {
    let mut offsets = Vec::with_capacity(ranges.len());
    let mut end = 0usize;
    for range in ranges {
        let offset = end.next_multiple_of(4) + range.start % 4;
        offsets.push(offset);
        end = offset + range.len();
    }
    // The lowest start among the ranges after each one.
    let mut later_start = vec![bin.len(); ranges.len()];
    for k in (1..ranges.len()).rev() {
        later_start[k - 1] = later_start[k].min(ranges[k].start);
    }
    let in_place = ranges
        .iter()
        .zip(&offsets)
        .zip(&later_start)
        .all(|((range, &offset), &limit)| range.end <= bin.len() && offset + range.len() <= limit);
    if !in_place {
        return keep_ranges_by_copy(&bin, ranges);
    }
    let mut end = 0;
    for (range, &offset) in ranges.iter().zip(&offsets) {
        bin.copy_within(range.clone(), offset);
        bin[end..offset].fill(0);
        end = offset + range.len();
    }
    bin.truncate(end);
    (bin, offsets)
}

/// [`keep_ranges`] by appending each range to a new buffer.
pub(crate) fn keep_ranges_by_copy(bin: &[u8], ranges: &[Range<usize>]) -> (Vec<u8>, Vec<usize>) {
    let mut kept = GlbBuilder::new(Map::new());
    let offsets = ranges
        .iter()
        .map(|range| kept.append_bytes(&bin[range.clone()], range.start))
        .collect();
    (kept.bin, offsets)
}

/// Components per element of the accessor types the writers use.
fn components_of(type_name: &str) -> usize {
    match type_name {
        "SCALAR" => 1,
        "VEC2" => 2,
        "VEC3" => 3,
        "VEC4" => 4,
        "MAT4" => 16,
        other => unreachable!("writers never use accessor type {other}"),
    }
}

/// Per-component minimum and maximum of flattened elements with `components` each.
pub(crate) fn component_bounds(values: &[f32], components: usize) -> (Vec<f32>, Vec<f32>) {
    let mut min = vec![f32::INFINITY; components];
    let mut max = vec![f32::NEG_INFINITY; components];
    for element in values.chunks_exact(components) {
        for (c, &v) in element.iter().enumerate() {
            min[c] = min[c].min(v);
            max[c] = max[c].max(v);
        }
    }
    (min, max)
}

/// [`component_bounds`] of `points` (each point's x, y, z as the components), taken from the
/// points instead of a flattened copy of them: the same `f32::min`/`max` in the same order.
pub(crate) fn point_bounds(points: &[glam::Vec3]) -> ([f32; 3], [f32; 3]) {
    let mut min = [f32::INFINITY; 3];
    let mut max = [f32::NEG_INFINITY; 3];
    for p in points {
        for (c, v) in p.to_array().into_iter().enumerate() {
            min[c] = min[c].min(v);
            max[c] = max[c].max(v);
        }
    }
    (min, max)
}

/// The smallest index component type for vertex indices below `vertex_count`.
fn index_component(vertex_count: usize) -> ComponentType {
    // 65535 is the primitive-restart value of UNSIGNED_SHORT and may not be used.
    if vertex_count <= 65535 {
        ComponentType::U16
    } else {
        ComponentType::U32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bounds of points are those of their flattened components, signed zeros and
    /// infinities included.
    #[test]
    fn point_bounds_match_the_flattened_bounds() {
        use glam::Vec3;
        let points = [
            Vec3::new(0.0, -0.0, 1.5),
            Vec3::new(-0.0, 0.0, -2.0),
            Vec3::new(3.0, f32::INFINITY, -0.0),
            Vec3::new(f32::NEG_INFINITY, 1e-30, 0.0),
            Vec3::new(0.25, -1e30, 7.0),
        ];
        for n in 0..=points.len() {
            let flat: Vec<f32> = points[..n].iter().flat_map(|p| p.to_array()).collect();
            let (min, max) = point_bounds(&points[..n]);
            let expected = component_bounds(&flat, 3);
            let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&min), bits(&expected.0), "{n} points");
            assert_eq!(bits(&max), bits(&expected.1), "{n} points");
        }
    }

    /// Kept ranges moved within the buffer are the bytes of the copying reference, with
    /// the reference's offsets, for ranges in order with and without gaps (some cases move
    /// a range forward, some cannot be done in place), out of order and overlapping.
    #[test]
    fn ranges_kept_in_place_match_the_copy() {
        let bin: Vec<u8> = (0..400u32).map(|i| (i * 7 + 3) as u8).collect();
        let mut cases: Vec<Vec<Range<usize>>> = vec![
            vec![],
            vec![0..5, 6..10, 10..11, 17..40],
            vec![3..9, 20..33, 40..41, 64..100, 150..200],
            vec![50..60, 10..20],
            vec![10..30, 20..40],
            vec![0..400],
        ];
        // Ranges in order with random gaps (zero included) and lengths, and ranges laid out
        // as a rewritten document's views are (each at the next multiple of 4 after the
        // previous one, plus its phase, possibly a multiple of 4 further): those are all
        // kept in place.
        let mut state = 12345u64;
        let mut next = |n: u64| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 33) % n) as usize
        };
        let mut written = Vec::new();
        for case in 0..400 {
            let mut ranges = Vec::new();
            let mut at = next(8);
            while at < bin.len() {
                let end = (at + next(24)).min(bin.len());
                ranges.push(at..end);
                at = match case % 2 {
                    0 => end + next(6),
                    _ => end.next_multiple_of(4) + 4 * next(3) + next(4),
                };
            }
            if case % 2 == 1 {
                written.push(cases.len());
            }
            cases.push(ranges);
        }
        for (k, ranges) in cases.iter().enumerate() {
            let original = bin.clone();
            let start = original.as_ptr();
            let kept = keep_ranges(original, ranges);
            assert!(
                kept.0.as_ptr() == start || !written.contains(&k),
                "{ranges:?} not kept in place"
            );
            assert_eq!(kept, keep_ranges_by_copy(&bin, ranges), "{ranges:?}");
        }
    }
}

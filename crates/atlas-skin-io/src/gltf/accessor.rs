//! Typed reads of glTF accessors (glTF 2.0 §3.6.2), every byte range checked against its
//! bufferView and buffer before it is read.

use super::document::{opt_str, Document, Location};
use crate::IoError;
use serde_json::Value;
use std::fmt::Display;

/// An accessor's component type (`accessor.componentType`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum ComponentType {
    I8,
    U8,
    I16,
    U16,
    U32,
    F32,
}

impl ComponentType {
    fn from_code(code: u64) -> Option<Self> {
        Some(match code {
            5120 => Self::I8,
            5121 => Self::U8,
            5122 => Self::I16,
            5123 => Self::U16,
            5125 => Self::U32,
            5126 => Self::F32,
            _ => return None,
        })
    }

    /// The glTF code of this component type.
    pub fn code(self) -> u32 {
        match self {
            Self::I8 => 5120,
            Self::U8 => 5121,
            Self::I16 => 5122,
            Self::U16 => 5123,
            Self::U32 => 5125,
            Self::F32 => 5126,
        }
    }

    /// Size of one component in bytes.
    pub fn size(self) -> usize {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::U32 | Self::F32 => 4,
        }
    }

    /// One component as a float. Normalized integers map to [0, 1] or [-1, 1] by the
    /// formulas of glTF 2.0 §3.11 (e.g. `f = max(c / 127, -1)` for signed bytes).
    #[inline]
    fn decode_f32(self, b: &[u8], normalized: bool) -> f32 {
        let (value, scale) = match self {
            Self::I8 => (b[0] as i8 as f32, 127.0),
            Self::U8 => (b[0] as f32, 255.0),
            Self::I16 => (i16::from_le_bytes([b[0], b[1]]) as f32, 32767.0),
            Self::U16 => (u16::from_le_bytes([b[0], b[1]]) as f32, 65535.0),
            Self::U32 => (u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32, 1.0),
            Self::F32 => return f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        };
        if normalized {
            (value / scale).max(-1.0)
        } else {
            value
        }
    }

    fn is_unsigned_integer(self) -> bool {
        matches!(self, Self::U8 | Self::U16 | Self::U32)
    }

    /// One unsigned integer component; `None` for signed and float types.
    #[inline]
    fn decode_u32(self, b: &[u8]) -> Option<u32> {
        match self {
            Self::U8 => Some(b[0] as u32),
            Self::U16 => Some(u16::from_le_bytes([b[0], b[1]]) as u32),
            Self::U32 => Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Self::I8 | Self::I16 | Self::F32 => None,
        }
    }
}

/// Number of components of an accessor `type`.
fn components_of(type_name: &str) -> Option<usize> {
    Some(match type_name {
        "SCALAR" => 1,
        "VEC2" => 2,
        "VEC3" => 3,
        "VEC4" => 4,
        "MAT2" => 4,
        "MAT3" => 9,
        "MAT4" => 16,
        _ => return None,
    })
}

/// Bytes of one element of the accessor JSON `object`, from its `componentType` and
/// `type`; `None` when either is not a glTF one, and for MAT2/MAT3 of 1- or 2-byte
/// components, whose columns are padded to 4 bytes (glTF 2.0 §3.6.2.4).
pub(crate) fn element_size(object: &Value) -> Option<usize> {
    let component = object
        .get("componentType")
        .and_then(Value::as_u64)
        .and_then(ComponentType::from_code)?;
    let type_name = opt_str(object, "type")?;
    if matches!(type_name, "MAT2" | "MAT3") && component.size() < 4 {
        return None;
    }
    Some(components_of(type_name)? * component.size())
}

/// Largest element count of an accessor without a bufferView (all zeros, possibly made
/// sparse): such an accessor has no bytes to bound its count, so a limit keeps a bad file
/// from asking for an arbitrary allocation.
const MAX_ZERO_FILLED_ELEMENTS: usize = 1 << 24;

/// Elements laid out with a stride: element i is `bytes[i * stride..][..element_size]`.
struct Strided<'a> {
    bytes: &'a [u8],
    stride: usize,
}

/// Sparse substitution: element `indices[k]` takes the k-th (tightly packed) value.
struct Sparse<'a> {
    indices: Vec<u32>,
    values: Strided<'a>,
}

/// One accessor, validated: its ranges lie inside its bufferViews and buffers.
struct Accessor<'a> {
    component: ComponentType,
    components: usize,
    count: usize,
    normalized: bool,
    dense: Option<Strided<'a>>,
    sparse: Option<Sparse<'a>>,
}

impl Accessor<'_> {
    fn element_size(&self) -> usize {
        self.components * self.component.size()
    }

    /// Bytes [`Accessor::decode`] allocates: 4 per component (f32 or u32), and 4 per
    /// sparse index.
    fn decoded_bytes(&self) -> u64 {
        let sparse = self.sparse.as_ref().map_or(0, |s| s.indices.len() as u64);
        (self.count as u64)
            .saturating_mul(self.components as u64)
            .saturating_add(sparse)
            .saturating_mul(4)
    }

    /// All elements' components, flattened, decoded by `decode` from each component's
    /// bytes; missing dense data reads as `zero`. Tightly packed elements (the usual
    /// layout) are decoded in one pass over their bytes.
    fn decode<T: Copy>(&self, zero: T, decode: impl Fn(&[u8]) -> T) -> Vec<T> {
        let size = self.component.size();
        let element_size = self.element_size();
        let mut out = Vec::with_capacity(self.count * self.components);
        let push_element = |out: &mut Vec<T>, bytes: &[u8]| {
            out.extend(bytes[..element_size].chunks_exact(size).map(&decode));
        };
        match &self.dense {
            Some(dense) if dense.stride == element_size => {
                let bytes = &dense.bytes[..self.count * element_size];
                out.extend(bytes.chunks_exact(size).map(&decode));
            }
            Some(dense) => {
                for i in 0..self.count {
                    push_element(&mut out, &dense.bytes[i * dense.stride..]);
                }
            }
            None => out.resize(self.count * self.components, zero),
        }
        if let Some(sparse) = &self.sparse {
            for (k, &target) in sparse.indices.iter().enumerate() {
                let mut element = Vec::with_capacity(self.components);
                push_element(
                    &mut element,
                    &sparse.values.bytes[k * sparse.values.stride..],
                );
                let start = target as usize * self.components;
                out[start..start + self.components].copy_from_slice(&element);
            }
        }
        out
    }
}

/// Bytes of bufferView `view` and its byteStride, checked against its buffer.
fn view_bytes<'a>(doc: &Document<'a>, view: usize) -> Result<(&'a [u8], Option<usize>), IoError> {
    let location = Location::item("bufferViews", view);
    let object = doc.item("bufferViews", view)?;
    let buffer = doc.index(object, &location, "buffer")?;
    let offset = doc.opt_index(object, &location, "byteOffset")?.unwrap_or(0);
    let length = doc.index(object, &location, "byteLength")?;
    let stride = doc.opt_index(object, &location, "byteStride")?;
    let data = doc.buffers.get(buffer).ok_or_else(|| {
        doc.error(format!(
            "{location}.buffer is {buffer} but the document has {} buffers",
            doc.buffers.len()
        ))
    })?;
    let bytes = offset
        .checked_add(length)
        .and_then(|end| data.get(offset..end))
        .ok_or_else(|| {
            doc.error(format!(
                "{location} (bytes {offset}..{offset}+{length}) is out of range of buffers[{buffer}] \
                 ({} bytes)",
                data.len()
            ))
        })?;
    if stride.is_some_and(|s| s == 0) {
        return Err(doc.error(format!("{location}.byteStride is 0")));
    }
    Ok((bytes, stride))
}

/// `count` elements of `element_size` bytes starting at `offset` of `view`, with the
/// view's stride (tightly packed when `allow_stride` is false or the view has none).
fn strided<'a>(
    doc: &Document<'a>,
    location: &dyn Display,
    view: usize,
    offset: usize,
    count: usize,
    element_size: usize,
    allow_stride: bool,
) -> Result<Strided<'a>, IoError> {
    let (bytes, view_stride) = view_bytes(doc, view)?;
    let stride = match view_stride {
        Some(stride) if allow_stride => stride,
        _ => element_size,
    };
    if stride < element_size {
        return Err(doc.error(format!(
            "{location}: bufferViews[{view}].byteStride {stride} is smaller than the element \
             size {element_size}"
        )));
    }
    let needed = match count {
        0 => Some(0),
        _ => (count - 1)
            .checked_mul(stride)
            .and_then(|n| n.checked_add(element_size)),
    };
    let bytes = needed
        .and_then(|needed| offset.checked_add(needed))
        .and_then(|end| bytes.get(offset..end))
        .ok_or_else(|| {
            doc.error(format!(
                "{location}: {count} elements of {element_size} bytes (stride {stride}) from byte \
                 {offset} are out of range of bufferViews[{view}] ({} bytes)",
                bytes.len()
            ))
        })?;
    Ok(Strided { bytes, stride })
}

/// Accessor `index`, checked to have type `expected_type` (one of SCALAR, VEC2..4, MAT4:
/// types whose elements have no column padding) and in-range data.
fn accessor<'a>(
    doc: &Document<'a>,
    index: usize,
    expected_type: &str,
) -> Result<Accessor<'a>, IoError> {
    let location = Location::item("accessors", index);
    let object = doc.item("accessors", index)?;
    let code = object.get("componentType").and_then(Value::as_u64);
    let component = code.and_then(ComponentType::from_code).ok_or_else(|| {
        doc.error(format!(
            "{location}.componentType is {}, not a glTF component type",
            object.get("componentType").unwrap_or(&Value::Null)
        ))
    })?;
    let type_name = opt_str(object, "type").unwrap_or("");
    let components = components_of(type_name)
        .ok_or_else(|| doc.error(format!("{location}.type {type_name:?} is not a glTF type")))?;
    if type_name != expected_type {
        return Err(doc.error(format!(
            "{location} has type {type_name}, expected {expected_type}"
        )));
    }
    let count = doc.index(object, &location, "count")?;
    let normalized = object
        .get("normalized")
        .and_then(Value::as_bool)
        .unwrap_or(false);
    let element_size = components * component.size();
    let dense = match doc.opt_index(object, &location, "bufferView")? {
        Some(view) => {
            let offset = doc.opt_index(object, &location, "byteOffset")?.unwrap_or(0);
            Some(strided(
                doc,
                &location,
                view,
                offset,
                count,
                element_size,
                true,
            )?)
        }
        None if count > MAX_ZERO_FILLED_ELEMENTS => {
            return Err(doc.error(format!(
                "{location} has no bufferView and a count of {count} (more than \
                 {MAX_ZERO_FILLED_ELEMENTS})"
            )))
        }
        None => None,
    };
    let sparse = match object.get("sparse") {
        None => None,
        Some(sparse) => Some(sparse_part(doc, &location, sparse, count, element_size)?),
    };
    Ok(Accessor {
        component,
        components,
        count,
        normalized,
        dense,
        sparse,
    })
}

/// The `sparse` part of an accessor with `count` elements.
fn sparse_part<'a>(
    doc: &Document<'a>,
    location: &dyn Display,
    sparse: &Value,
    count: usize,
    element_size: usize,
) -> Result<Sparse<'a>, IoError> {
    let location = format!("{location}.sparse");
    let sparse_count = doc.index(sparse, &location, "count")?;
    let indices = sparse
        .get("indices")
        .ok_or_else(|| doc.error(format!("{location} has no indices")))?;
    let values = sparse
        .get("values")
        .ok_or_else(|| doc.error(format!("{location} has no values")))?;
    let indices_location = format!("{location}.indices");
    let index_type = indices
        .get("componentType")
        .and_then(Value::as_u64)
        .and_then(ComponentType::from_code)
        .filter(|c| c.is_unsigned_integer())
        .ok_or_else(|| doc.error(format!("{indices_location}.componentType is not unsigned")))?;
    let index_data = strided(
        doc,
        &indices_location,
        doc.index(indices, &indices_location, "bufferView")?,
        doc.opt_index(indices, &indices_location, "byteOffset")?
            .unwrap_or(0),
        sparse_count,
        index_type.size(),
        false,
    )?;
    let indices: Vec<u32> = index_data
        .bytes
        .chunks_exact(index_type.size())
        .filter_map(|b| index_type.decode_u32(b))
        .collect();
    if let Some(bad) = indices.iter().find(|&&i| i as usize >= count) {
        return Err(doc.error(format!(
            "{indices_location}: index {bad} is out of range of the accessor's {count} elements"
        )));
    }
    let values_location = format!("{location}.values");
    let values = strided(
        doc,
        &values_location,
        doc.index(values, &values_location, "bufferView")?,
        doc.opt_index(values, &values_location, "byteOffset")?
            .unwrap_or(0),
        sparse_count,
        element_size,
        false,
    )?;
    Ok(Sparse { indices, values })
}

/// Prefixes the message of an [`IoError::Invalid`] with what the accessor is used as.
fn used_as(error: IoError, role: &dyn Display) -> IoError {
    match error {
        IoError::Invalid { path, message } => IoError::Invalid {
            path,
            message: format!("{role}: {message}"),
        },
        other => other,
    }
}

/// Accessor `index` of type `expected_type`, used as `role` (named in errors), as floats,
/// flattened (#elements × components). Integer components are converted, normalized ones
/// by glTF 2.0 §3.11.
pub(crate) fn read_floats(
    doc: &Document,
    index: usize,
    expected_type: &str,
    role: &dyn Display,
) -> Result<Vec<f32>, IoError> {
    let accessor = accessor(doc, index, expected_type).map_err(|e| used_as(e, role))?;
    doc.charge(accessor.decoded_bytes(), role)?;
    let (component, normalized) = (accessor.component, accessor.normalized);
    // The common component type with its decoding inlined into the loop.
    Ok(match component {
        ComponentType::F32 => accessor.decode(0.0, |b| ComponentType::F32.decode_f32(b, false)),
        _ => accessor.decode(0.0, |b| component.decode_f32(b, normalized)),
    })
}

/// Accessor `index` of type `expected_type`, used as `role` (named in errors), as unsigned
/// integers, flattened; the component type must be UNSIGNED_BYTE, UNSIGNED_SHORT or
/// UNSIGNED_INT and not normalized.
pub(crate) fn read_uints(
    doc: &Document,
    index: usize,
    expected_type: &str,
    role: &dyn Display,
) -> Result<Vec<u32>, IoError> {
    let accessor = accessor(doc, index, expected_type).map_err(|e| used_as(e, role))?;
    doc.charge(accessor.decoded_bytes(), role)?;
    let component = accessor.component;
    if !component.is_unsigned_integer() || accessor.normalized {
        return Err(doc.error(format!(
            "{role}: accessors[{index}] has component type {}{}, expected an unsigned integer \
             type",
            component.code(),
            if accessor.normalized {
                " (normalized)"
            } else {
                ""
            }
        )));
    }
    // Each component type with its decoding inlined into the loop (one match per
    // accessor, not one per component; the generic decoding is the reference the tests
    // compare with).
    Ok(match component {
        ComponentType::U8 => accessor.decode(0, |b| ComponentType::U8.decode_u32(b).unwrap_or(0)),
        ComponentType::U16 => accessor.decode(0, |b| ComponentType::U16.decode_u32(b).unwrap_or(0)),
        _ => accessor.decode(0, |b| ComponentType::U32.decode_u32(b).unwrap_or(0)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;
    use std::path::Path;

    fn doc_with(json: &Value, buffers: &[Vec<u8>], run: impl FnOnce(&Document)) {
        run(&Document {
            json,
            buffers,
            path: Path::new("t.gltf"),
            budget: &crate::gltf::budget::DecodeBudget::for_input(0),
        });
    }

    #[test]
    fn strided_normalized_and_sparse_reads() {
        let buffer = vec![vec![0u8, 255, 7, 7, 128, 64, 7, 7, 1, 0, 9, 0]];
        let json = json!({
            "bufferViews": [
                {"buffer": 0, "byteOffset": 0, "byteLength": 8, "byteStride": 4},
                {"buffer": 0, "byteOffset": 8, "byteLength": 4}
            ],
            "accessors": [
                {"bufferView": 0, "componentType": 5121, "normalized": true, "count": 2, "type": "VEC2"},
                {"bufferView": 0, "componentType": 5121, "count": 3, "type": "VEC2"},
                {"componentType": 5121, "count": 3, "type": "SCALAR",
                 "sparse": {"count": 1, "indices": {"bufferView": 1, "componentType": 5121},
                            "values": {"bufferView": 1, "byteOffset": 2}}}
            ]
        });
        doc_with(&json, &buffer, |doc| {
            let v = read_floats(doc, 0, "VEC2", &"test").unwrap();
            assert_eq!(v, vec![0.0, 1.0, 128.0 / 255.0, 64.0 / 255.0]);
            let invalid = |result: Result<Vec<_>, IoError>, words: &str| matches!(&result, Err(IoError::Invalid { message, .. }) if message.contains(words));
            let past_the_view = read_floats(doc, 1, "VEC2", &"test");
            assert!(
                invalid(past_the_view, "test"),
                "third element past the view"
            );
            assert!(
                invalid(read_floats(doc, 0, "VEC3", &"test"), "VEC"),
                "wrong type"
            );
            assert_eq!(
                read_uints(doc, 2, "SCALAR", &"test").unwrap(),
                vec![0, 9, 0]
            );
            assert!(
                matches!(
                    read_uints(doc, 0, "VEC2", &"test"),
                    Err(IoError::Invalid { .. })
                ),
                "normalized is not an index"
            );
        });
    }

    /// Unsigned integers of every width, tightly packed and strided, read as the generic
    /// per-component decoding reads them.
    #[test]
    fn unsigned_integers_of_every_width_match_the_generic_decoding() {
        let bytes: Vec<u8> = (0..96u32).map(|i| (i * 37 + 11) as u8).collect();
        for component in [ComponentType::U8, ComponentType::U16, ComponentType::U32] {
            let size = component.size();
            for stride in [2 * size, 2 * size + 4] {
                let count = bytes.len() / stride;
                let json = json!({
                    "bufferViews": [{"buffer": 0, "byteLength": bytes.len(), "byteStride": stride}],
                    "accessors": [{"bufferView": 0, "componentType": component.code(),
                                   "count": count, "type": "VEC2"}]
                });
                let expected: Vec<u32> = (0..count)
                    .flat_map(|i| (0..2).map(move |c| i * stride + c * size))
                    .map(|at| component.decode_u32(&bytes[at..]).unwrap())
                    .collect();
                doc_with(&json, std::slice::from_ref(&bytes), |doc| {
                    let read = read_uints(doc, 0, "VEC2", &"test").unwrap();
                    assert_eq!(read, expected, "{component:?}, stride {stride}");
                });
            }
        }
    }
}

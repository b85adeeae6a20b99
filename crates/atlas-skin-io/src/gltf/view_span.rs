//! The part of a bufferView that its accessors still use, so that the bytes a dropped
//! accessor had in a shared view (e.g. old JOINTS_0 next to TEXCOORD_0) can be cut off.

use super::accessor::element_size;
use serde_json::{Map, Value};
use std::ops::Range;

/// Bytes `offset..offset + (count − 1) · stride + element_size` of its bufferView that the
/// accessor JSON `accessor` reads (`stride`: the view's byteStride, or the element size);
/// `None` when its layout cannot be read.
fn accessor_span(accessor: &Value, view_stride: Option<usize>) -> Option<Range<usize>> {
    let field = |key: &str| {
        accessor
            .get(key)
            .and_then(Value::as_u64)
            .map(|v| v as usize)
    };
    let offset = field("byteOffset").unwrap_or(0);
    let count = field("count")?;
    let size = element_size(accessor)?;
    let length = match count {
        0 => 0,
        _ => (count - 1)
            .checked_mul(view_stride.unwrap_or(size))?
            .checked_add(size)?,
    };
    Some(offset..offset.checked_add(length)?)
}

/// For every bufferView marked in `shrinkable`, the span `cut..end` of its bytes that the
/// accessors marked in `kept` read through their `bufferView`, with `cut` rounded down to
/// a multiple of 4 so that the accessors keep their alignment once their `byteOffset`
/// loses `cut`. `None` for the other views, for views an image or a sparse part also uses
/// (they read the whole view), and for views with an accessor whose layout cannot be read.
pub(crate) fn used_spans(
    json: &Map<String, Value>,
    kept: &[bool],
    shrinkable: &[bool],
) -> Vec<Option<Range<usize>>> {
    let items = |key: &str| match json.get(key) {
        Some(Value::Array(items)) => items.as_slice(),
        _ => &[],
    };
    let view_index = |value: Option<&Value>| value.and_then(Value::as_u64).map(|v| v as usize);
    let views = items("bufferViews");
    let mut spans: Vec<Option<Range<usize>>> = vec![None; shrinkable.len()];
    let mut whole = vec![false; shrinkable.len()];
    let mut mark_whole = |view: Option<usize>| {
        if let Some(slot) = view.and_then(|v| whole.get_mut(v)) {
            *slot = true;
        }
    };
    for image in items("images") {
        mark_whole(view_index(image.get("bufferView")));
    }
    let kept_accessors = items("accessors")
        .iter()
        .zip(kept)
        .filter(|(_, &k)| k)
        .map(|(a, _)| a);
    for accessor in kept_accessors {
        for part in ["indices", "values"] {
            let sparse_part = accessor.get("sparse").and_then(|s| s.get(part));
            mark_whole(view_index(sparse_part.and_then(|p| p.get("bufferView"))));
        }
        let Some(view) = view_index(accessor.get("bufferView")) else {
            continue;
        };
        if !shrinkable.get(view).copied().unwrap_or(false) {
            continue;
        }
        let stride = views
            .get(view)
            .and_then(|v| view_index(v.get("byteStride")));
        match accessor_span(accessor, stride) {
            Some(span) => {
                let merged = match spans[view].take() {
                    Some(old) => old.start.min(span.start)..old.end.max(span.end),
                    None => span,
                };
                spans[view] = Some(merged);
            }
            None => mark_whole(Some(view)),
        }
    }
    spans
        .into_iter()
        .zip(whole)
        .map(|(span, whole)| {
            span.filter(|_| !whole)
                .map(|span| span.start / 4 * 4..span.end)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn spans_cover_the_kept_accessors_and_stay_whole_when_unsure() {
        let json = json!({
            "bufferViews": [{"byteStride": 8}, {}, {}, {}],
            "accessors": [
                {"bufferView": 0, "byteOffset": 6, "count": 3, "componentType": 5123, "type": "VEC2"},
                {"bufferView": 0, "byteOffset": 40, "count": 2, "componentType": 5123, "type": "VEC2"},
                {"bufferView": 1, "count": 2, "componentType": 5126, "type": "VEC3"},
                {"bufferView": 2, "count": 2, "componentType": 5121, "type": "MAT2"},
                {"bufferView": 3, "count": 2, "componentType": 5126, "type": "SCALAR"}
            ],
            "images": [{"bufferView": 3}]
        });
        let Value::Object(json) = json else {
            unreachable!()
        };
        let kept = [true, true, true, true, true];
        let spans = used_spans(&json, &kept, &[true, false, true, true]);
        // Accessor 0 reads 6..6 + 2 × 8 + 4 = 26, accessor 1 reads 40..40 + 8 + 4 = 52.
        assert_eq!(spans, [Some(4..52), None, None, None]);
        let spans = used_spans(&json, &[false, true, true, true, true], &[true; 4]);
        assert_eq!(spans[0], Some(40..52));
        assert_eq!(spans[1], Some(0..24));
    }
}

//! The glTF containers: a `.glb` binary (12-byte header, JSON chunk, optional BIN chunk), or
//! a `.gltf` JSON file whose buffers are base64 `data:` URIs or files beside it (see
//! [`DocumentFolder`] for which files a document may name).

use super::file_access::DocumentFolder;
use crate::IoError;
use serde_json::Value;
use std::ops::Range;
use std::path::Path;

/// The first 4 bytes of a GLB file (glTF 2.0 §4.4.2).
const GLB_MAGIC: &[u8; 4] = b"glTF";
const GLB_HEADER_BYTES: usize = 12;
const CHUNK_HEADER_BYTES: usize = 8;
const CHUNK_JSON: u32 = 0x4E4F_534A;
const CHUNK_BIN: u32 = 0x004E_4942;
/// The UTF-8 byte-order mark, which glTF JSON must not start with (glTF 2.0 asks for UTF-8
/// without BOM) but some exporters write.
const UTF8_BOM: &[u8; 3] = b"\xEF\xBB\xBF";

/// A glTF document as read: its JSON, the bytes of every buffer (in `buffers` order), of
/// every image given by `uri` (in `images` order; `None` for the others and for those left
/// out), warnings about tolerated departures from the format, and the bytes read in all
/// (the file, its buffers and images).
pub(crate) struct Container {
    pub json: Value,
    pub buffers: Vec<Vec<u8>>,
    pub images: Vec<Option<ImageBytes>>,
    pub warnings: Vec<String>,
    pub input_bytes: u64,
}

/// Reads the `.glb`, `.vrm` or `.gltf` file at `path` and every buffer it refers to.
///
/// The content decides the container: a file starting with `glTF` is a binary, anything
/// else must be a `.gltf` JSON file. JSON starting with a UTF-8 byte-order mark is read
/// with a warning.
pub(crate) fn read_container(path: &Path) -> Result<Container, IoError> {
    let mut bytes = crate::text::read_bytes(path)?;
    let file_bytes = bytes.len() as u64;
    let is_binary_name = matches!(extension(path).as_str(), "glb" | "vrm");
    let (json_range, bin_range) = if bytes.starts_with(GLB_MAGIC) {
        split_glb(path, &bytes)?
    } else if is_binary_name {
        let shown = &bytes[..bytes.len().min(4)];
        return Err(IoError::invalid(
            path,
            format!(
                "not a binary glTF: the file starts with {:?} instead of the magic \"glTF\"",
                String::from_utf8_lossy(shown)
            ),
        ));
    } else {
        (0..bytes.len(), None)
    };
    let mut warnings = Vec::new();
    let json_bytes = &bytes[json_range];
    let json_bytes = match json_bytes.strip_prefix(UTF8_BOM) {
        Some(rest) => {
            warnings.push(
                "the JSON starts with a UTF-8 byte-order mark, which glTF does not allow; \
                 ignored"
                    .to_string(),
            );
            rest
        }
        None => json_bytes,
    };
    let json = parse_json(path, json_bytes)?;
    // The BIN chunk becomes buffer 0 in the file's own allocation (moved to its start)
    // instead of a copy.
    let bin = bin_range.map(|range| {
        bytes.truncate(range.end);
        bytes.drain(..range.start);
        bytes
    });
    let mut folder = DocumentFolder::of(path);
    let buffers = load_buffers(path, &json, bin, &mut folder)?;
    let buffer_bytes = buffers.iter().map(|b| b.len() as u64).sum();
    let images = load_images(path, &json, buffer_bytes, &mut folder, &mut warnings)?;
    let image_bytes: u64 = images.iter().flatten().map(|i| i.bytes.len() as u64).sum();
    Ok(Container {
        json,
        buffers,
        images,
        warnings,
        input_bytes: file_bytes + buffer_bytes + image_bytes,
    })
}

/// Lower-case extension of `path`, empty when it has none.
fn extension(path: &Path) -> String {
    path.extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase()
}

fn read_u32(bytes: &[u8], at: usize) -> Option<u32> {
    let word = bytes.get(at..at.checked_add(4)?)?;
    Some(u32::from_le_bytes([word[0], word[1], word[2], word[3]]))
}

/// The byte ranges of a GLB file's JSON chunk and of its BIN chunk (if any), checking the
/// header and every chunk length against the file size.
pub(crate) fn split_glb(
    path: &Path,
    bytes: &[u8],
) -> Result<(Range<usize>, Option<Range<usize>>), IoError> {
    let error = |message: String| IoError::invalid(path, message);
    if bytes.len() < GLB_HEADER_BYTES {
        return Err(error(format!(
            "truncated glb: {} bytes, shorter than the 12-byte header",
            bytes.len()
        )));
    }
    let version = read_u32(bytes, 4).unwrap_or(0);
    if version != 2 {
        return Err(error(format!(
            "glb container version {version}, expected 2"
        )));
    }
    let declared = read_u32(bytes, 8).unwrap_or(0) as usize;
    if declared != bytes.len() {
        let what = if declared > bytes.len() {
            "truncated glb"
        } else {
            "bad glb length"
        };
        return Err(error(format!(
            "{what}: the header says {declared} bytes, the file has {}",
            bytes.len()
        )));
    }
    let mut json = None;
    let mut bin = None;
    let mut offset = GLB_HEADER_BYTES;
    let mut chunk_index = 0;
    while offset < bytes.len() {
        let (Some(length), Some(kind)) = (read_u32(bytes, offset), read_u32(bytes, offset + 4))
        else {
            return Err(error(format!(
                "truncated glb: chunk {chunk_index} header at byte {offset} runs past the end"
            )));
        };
        let start = offset + CHUNK_HEADER_BYTES;
        let end = start
            .checked_add(length as usize)
            .filter(|&e| e <= bytes.len());
        let Some(end) = end else {
            return Err(error(format!(
                "bad glb chunk length: chunk {chunk_index} at byte {offset} declares {length} \
                 bytes, only {} remain",
                bytes.len() - start
            )));
        };
        match (chunk_index, kind) {
            (0, CHUNK_JSON) => json = Some(start..end),
            (0, _) => {
                return Err(error(format!(
                    "the first glb chunk has type 0x{kind:08X}, expected JSON (0x{CHUNK_JSON:08X})"
                )))
            }
            (1, CHUNK_BIN) => bin = Some(start..end),
            // Unknown chunk types must be ignored (glTF 2.0 §4.4.3.1).
            _ => {}
        }
        offset = end;
        chunk_index += 1;
    }
    let json = json.ok_or_else(|| error("the glb has no JSON chunk".into()))?;
    Ok((json, bin))
}

/// Parses the JSON and checks that it is a glTF 2.x document (an object with `asset.version`
/// starting with "2.").
fn parse_json(path: &Path, bytes: &[u8]) -> Result<Value, IoError> {
    let json: Value = serde_json::from_slice(bytes)
        .map_err(|e| IoError::invalid(path, format!("invalid glTF JSON: {e}")))?;
    let version = json
        .get("asset")
        .and_then(|asset| asset.get("version"))
        .and_then(Value::as_str);
    match version {
        None => Err(IoError::invalid(
            path,
            "not a glTF document: the JSON has no \"asset\" object with a \"version\"",
        )),
        Some(v) if v.split('.').next() != Some("2") => Err(IoError::invalid(
            path,
            format!("glTF version {v:?} is not supported (expected 2.x)"),
        )),
        Some(_) => Ok(json),
    }
}

/// Largest total of bytes a document may load besides its own file: its external and
/// `data:` buffers and its images (docs/formats.md, "Memory").
pub const MAX_LOADED_BYTES: u64 = 1 << 30;

/// The bufferViews may span at most this many times the buffers' bytes, plus
/// [`VIEW_SLACK_BYTES`], in total: views may overlap, but every view is copied into a
/// skinned output, so 600 views over one buffer would multiply it 600 times.
const MAX_VIEW_OVERLAP: u64 = 2;
const VIEW_SLACK_BYTES: u64 = 1 << 20;

/// Loads every buffer of the document: the GLB BIN chunk for a buffer without `uri`, a
/// base64 `data:` URI, or a file inside the document's folder ([`DocumentFolder`]). The
/// declared byteLengths must add up to at most [`MAX_LOADED_BYTES`] before anything is
/// read; each buffer is cut to its `byteLength`, and must be at least that long.
fn load_buffers(
    path: &Path,
    json: &Value,
    bin: Option<Vec<u8>>,
    folder: &mut DocumentFolder,
) -> Result<Vec<Vec<u8>>, IoError> {
    let declared = top_level_array(path, json, "buffers")?;
    let mut lengths = Vec::with_capacity(declared.len());
    for (index, buffer) in declared.iter().enumerate() {
        let byte_length = buffer
            .get("byteLength")
            .and_then(Value::as_u64)
            .ok_or_else(|| {
                IoError::invalid(path, format!("buffers[{index}] has no valid byteLength"))
            })?;
        lengths.push(byte_length);
    }
    let total = lengths.iter().fold(0u64, |sum, &l| sum.saturating_add(l));
    if total > MAX_LOADED_BYTES {
        return Err(IoError::invalid(
            path,
            format!(
                "the buffers declare {total} bytes in total, more than the {MAX_LOADED_BYTES}                  a document may load"
            ),
        ));
    }
    let mut bin = bin;
    let mut buffers = Vec::with_capacity(declared.len());
    for (index, (buffer, &byte_length)) in declared.iter().zip(&lengths).enumerate() {
        let mut bytes = match buffer.get("uri") {
            None if index == 0 => bin.take().ok_or_else(|| {
                IoError::invalid(
                    path,
                    "buffers[0] has no uri and the file has no glb BIN chunk",
                )
            })?,
            None => {
                return Err(IoError::invalid(
                    path,
                    format!(
                        "buffers[{index}] has no uri (only buffer 0 may use the glb BIN chunk)"
                    ),
                ))
            }
            Some(Value::String(uri)) => {
                let user = format!("buffers[{index}]");
                folder
                    .read(uri, &user, byte_length, true)
                    .map_err(|e| IoError::invalid(path, format!("{user}: {e}")))?
                    .bytes
            }
            Some(_) => {
                return Err(IoError::invalid(
                    path,
                    format!("buffers[{index}].uri is not a string"),
                ))
            }
        };
        if (bytes.len() as u64) < byte_length {
            return Err(IoError::invalid(
                path,
                format!(
                    "buffers[{index}] has {} bytes, less than its byteLength {byte_length}",
                    bytes.len()
                ),
            ));
        }
        bytes.truncate(byte_length as usize);
        buffers.push(bytes);
    }
    check_view_total(path, json, total)?;
    Ok(buffers)
}

/// The most bytes the bufferViews over `buffer_bytes` of buffers may span in total:
/// [`MAX_VIEW_OVERLAP`] times them plus [`VIEW_SLACK_BYTES`].
pub(crate) fn view_span_limit(buffer_bytes: u64) -> u64 {
    buffer_bytes
        .saturating_mul(MAX_VIEW_OVERLAP)
        .saturating_add(VIEW_SLACK_BYTES)
}

/// The top-level array `key` of the document; empty when absent.
fn top_level_array<'a>(path: &Path, json: &'a Value, key: &str) -> Result<&'a [Value], IoError> {
    match json.get(key) {
        None => Ok(&[]),
        Some(Value::Array(items)) => Ok(items),
        Some(_) => Err(IoError::invalid(path, format!("\"{key}\" is not an array"))),
    }
}

/// The bufferViews may span at most [`MAX_VIEW_OVERLAP`] times the buffers' bytes plus
/// [`VIEW_SLACK_BYTES`].
fn check_view_total(path: &Path, json: &Value, buffer_bytes: u64) -> Result<(), IoError> {
    let views = top_level_array(path, json, "bufferViews")?;
    let spanned = views
        .iter()
        .filter_map(|view| view.get("byteLength").and_then(Value::as_u64))
        .fold(0u64, u64::saturating_add);
    let limit = view_span_limit(buffer_bytes);
    if spanned > limit {
        return Err(IoError::invalid(
            path,
            format!(
                "the bufferViews span {spanned} bytes in total, more than {MAX_VIEW_OVERLAP} \
                 times the {buffer_bytes} bytes of the buffers plus {VIEW_SLACK_BYTES}"
            ),
        ));
    }
    Ok(())
}

/// An image given by `uri`, as read: its bytes and the media type a `data:` URI declared.
#[derive(Clone)]
pub struct ImageBytes {
    pub bytes: Vec<u8>,
    pub media_type: Option<String>,
}

/// Loads every image given by `uri` (`None` for images in a bufferView). An image the
/// policy of [`DocumentFolder`] refuses, or one past [`MAX_LOADED_BYTES`] with the buffers,
/// is left out (`None`) with a warning naming it.
fn load_images(
    path: &Path,
    json: &Value,
    mut loaded: u64,
    folder: &mut DocumentFolder,
    warnings: &mut Vec<String>,
) -> Result<Vec<Option<ImageBytes>>, IoError> {
    let images = top_level_array(path, json, "images")?;
    let mut out = Vec::with_capacity(images.len());
    for (index, image) in images.iter().enumerate() {
        let Some(uri) = image.get("uri").and_then(Value::as_str) else {
            out.push(None);
            continue;
        };
        let user = format!("images[{index}]");
        let remaining = MAX_LOADED_BYTES.saturating_sub(loaded);
        match folder.read(uri, &user, remaining, false) {
            Ok(read) => {
                loaded += read.bytes.len() as u64;
                out.push(Some(ImageBytes {
                    bytes: read.bytes,
                    media_type: read.media_type,
                }));
            }
            Err(e) => {
                warnings.push(format!("{user} left out: {e}"));
                out.push(None);
            }
        }
    }
    Ok(out)
}

/// A GLB file holding `json` and, when `bin` is not empty, a BIN chunk. Chunks are padded
/// to 4 bytes: JSON with spaces, BIN with zeros (glTF 2.0 §4.4.3).
///
/// The JSON is serialised into bytes directly (the compact form `Value`'s `Display`
/// writes, without going through the formatter and a `String`) after room for the
/// header, and the header and JSON are then put in front of the BIN chunk inside `bin`'s
/// own allocation (moving it there, in the room [`super::builder::GlbBuilder::with_capacity`]
/// left when there is enough) instead of copying both into a third buffer.
pub(crate) fn glb_bytes(json: &Value, mut bin: Vec<u8>) -> Vec<u8> {
    let mut head = vec![0; GLB_HEADER_BYTES + CHUNK_HEADER_BYTES];
    serde_json::to_writer(&mut head, json).expect("a JSON value serialises into memory");
    let json_end = head.len().next_multiple_of(4);
    head.resize(json_end, b' ');
    let json_length = json_end - GLB_HEADER_BYTES - CHUNK_HEADER_BYTES;
    let bin_chunk_len = bin.len().next_multiple_of(4);
    let mut total = json_end;
    if !bin.is_empty() {
        total += CHUNK_HEADER_BYTES + bin_chunk_len;
        head.extend_from_slice(&(bin_chunk_len as u32).to_le_bytes());
        head.extend_from_slice(&CHUNK_BIN.to_le_bytes());
    }
    head[0..4].copy_from_slice(GLB_MAGIC);
    head[4..8].copy_from_slice(&2u32.to_le_bytes());
    head[8..12].copy_from_slice(&(total as u32).to_le_bytes());
    head[12..16].copy_from_slice(&(json_length as u32).to_le_bytes());
    head[16..20].copy_from_slice(&CHUNK_JSON.to_le_bytes());
    if bin.is_empty() {
        return head;
    }
    bin.resize(bin_chunk_len, 0);
    bin.resize(total, 0);
    bin.copy_within(0..bin_chunk_len, head.len());
    bin[..head.len()].copy_from_slice(&head);
    bin
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glb_round_trips_through_split() {
        let json = serde_json::json!({"asset": {"version": "2.0"}});
        let bytes = glb_bytes(&json, vec![1, 2, 3]);
        assert_eq!(bytes.len() % 4, 0);
        let (json_range, bin) = split_glb(Path::new("x.glb"), &bytes).unwrap();
        assert_eq!(
            parse_json(Path::new("x.glb"), &bytes[json_range]).unwrap(),
            json
        );
        assert_eq!(&bytes[bin.unwrap()][..3], &[1, 2, 3]);
    }
}

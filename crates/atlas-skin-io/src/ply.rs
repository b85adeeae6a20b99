//! Stanford PLY meshes, ASCII and binary (little and big endian): the `vertex` element's
//! x, y, z and the `face` element's vertex index lists, fan-triangulated.

use crate::text::{read_bytes, Tokens};
use crate::{IoError, TriangleMesh};
use glam::Vec3;
use std::path::Path;

/// Reads the PLY at `path`. Other elements and properties are read past and ignored.
pub fn read(path: &Path) -> Result<TriangleMesh, IoError> {
    let bytes = read_bytes(path)?;
    let header = Header::parse(path, &bytes)?;
    match header.format {
        Format::Ascii => {
            let text = String::from_utf8_lossy(&bytes);
            let mut tokens = Tokens::new(path, &text, None);
            // Skip the header so that error lines count from the top of the file.
            while tokens.word("end_header")? != "end_header" {}
            read_elements(path, &header.elements, &mut Ascii(tokens))
        }
        Format::Binary { big_endian } => {
            let mut binary = Binary {
                path,
                bytes: &bytes[header.body_start..],
                offset: header.body_start,
                big_endian,
            };
            read_elements(path, &header.elements, &mut binary)
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Format {
    Ascii,
    Binary { big_endian: bool },
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn from_name(name: &str) -> Option<Self> {
        Some(match name {
            "char" | "int8" => Self::I8,
            "uchar" | "uint8" => Self::U8,
            "short" | "int16" => Self::I16,
            "ushort" | "uint16" => Self::U16,
            "int" | "int32" => Self::I32,
            "uint" | "uint32" => Self::U32,
            "float" | "float32" => Self::F32,
            "double" | "float64" => Self::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 | Self::F32 => 4,
            Self::F64 => 8,
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
enum Property {
    Scalar {
        name: String,
        ty: Scalar,
    },
    List {
        name: String,
        count: Scalar,
        item: Scalar,
    },
}

impl Property {
    fn name(&self) -> &str {
        match self {
            Self::Scalar { name, .. } | Self::List { name, .. } => name,
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
struct Element {
    name: String,
    count: usize,
    properties: Vec<Property>,
}

struct Header {
    format: Format,
    elements: Vec<Element>,
    /// Byte offset of the first byte after the `end_header` line.
    body_start: usize,
}

impl Header {
    fn parse(path: &Path, bytes: &[u8]) -> Result<Self, IoError> {
        let mut format = None;
        let mut elements: Vec<Element> = Vec::new();
        let mut offset = 0;
        let mut line = 0;
        loop {
            let Some(length) = bytes[offset..].iter().position(|&b| b == b'\n') else {
                return Err(IoError::invalid(
                    path,
                    "the PLY header has no end_header line",
                ));
            };
            line += 1;
            let text = String::from_utf8_lossy(&bytes[offset..offset + length]);
            offset += length + 1;
            let mut tokens = text.split_whitespace();
            let keyword = tokens.next().unwrap_or_default();
            let error = |message: String| IoError::syntax(path, line, message);
            if line == 1 {
                if keyword != "ply" {
                    return Err(error(
                        "not a PLY file (the first line is not \"ply\")".into(),
                    ));
                }
                continue;
            }
            match keyword {
                "format" => {
                    format = Some(match tokens.next() {
                        Some("ascii") => Format::Ascii,
                        Some("binary_little_endian") => Format::Binary { big_endian: false },
                        Some("binary_big_endian") => Format::Binary { big_endian: true },
                        other => {
                            return Err(error(format!(
                                "unknown PLY format {:?}",
                                other.unwrap_or_default()
                            )))
                        }
                    })
                }
                "element" => {
                    let name = tokens.next().unwrap_or_default().to_string();
                    let count = tokens
                        .next()
                        .and_then(|t| t.parse().ok())
                        .ok_or_else(|| error(format!("element {name:?} has no valid count")))?;
                    elements.push(Element {
                        name,
                        count,
                        properties: Vec::new(),
                    });
                }
                "property" => {
                    let words: Vec<&str> = tokens.collect();
                    let scalar = |name: &str| {
                        Scalar::from_name(name)
                            .ok_or_else(|| error(format!("unknown property type {name:?}")))
                    };
                    let property = match words.as_slice() {
                        ["list", count, item, name] => Property::List {
                            name: name.to_string(),
                            count: scalar(count)?,
                            item: scalar(item)?,
                        },
                        [ty, name] => Property::Scalar {
                            name: name.to_string(),
                            ty: scalar(ty)?,
                        },
                        _ => {
                            return Err(error(format!("malformed property line {:?}", text.trim())))
                        }
                    };
                    elements
                        .last_mut()
                        .ok_or_else(|| error("property before any element".into()))?
                        .properties
                        .push(property);
                }
                "end_header" => break,
                "comment" | "obj_info" | "" => {}
                other => return Err(error(format!("unknown header keyword {other:?}"))),
            }
        }
        let format =
            format.ok_or_else(|| IoError::invalid(path, "the PLY header has no format line"))?;
        Ok(Self {
            format,
            elements,
            body_start: offset,
        })
    }
}

/// Where the element values come from: ASCII tokens or binary bytes.
trait Values {
    /// The next value; `what` names it in an error.
    fn value(&mut self, ty: Scalar, what: &dyn Fn() -> String) -> Result<f64, IoError>;
}

struct Ascii<'a>(Tokens<'a>);

impl Values for Ascii<'_> {
    fn value(&mut self, _ty: Scalar, what: &dyn Fn() -> String) -> Result<f64, IoError> {
        let Some(token) = self.0.next_token() else {
            return Err(self
                .0
                .error(format!("unexpected end of file, expected {}", what())));
        };
        token.parse().map_err(|_| {
            self.0
                .error(format!("{}: {token:?} is not a number", what()))
        })
    }
}

struct Binary<'a> {
    path: &'a Path,
    bytes: &'a [u8],
    /// Offset of `bytes` in the file, for error messages.
    offset: usize,
    big_endian: bool,
}

impl Values for Binary<'_> {
    fn value(&mut self, ty: Scalar, what: &dyn Fn() -> String) -> Result<f64, IoError> {
        let size = ty.size();
        if self.bytes.len() < size {
            return Err(IoError::invalid(
                self.path,
                format!(
                    "the data ends at byte {} while reading {}",
                    self.offset + self.bytes.len(),
                    what()
                ),
            ));
        }
        let (head, rest) = self.bytes.split_at(size);
        self.bytes = rest;
        self.offset += size;
        let mut raw = [0u8; 8];
        raw[..size].copy_from_slice(head);
        if self.big_endian {
            raw[..size].reverse();
        }
        let [b0, b1, b2, b3, ..] = raw;
        Ok(match ty {
            Scalar::I8 => f64::from(b0 as i8),
            Scalar::U8 => f64::from(b0),
            Scalar::I16 => f64::from(i16::from_le_bytes([b0, b1])),
            Scalar::U16 => f64::from(u16::from_le_bytes([b0, b1])),
            Scalar::I32 => f64::from(i32::from_le_bytes([b0, b1, b2, b3])),
            Scalar::U32 => f64::from(u32::from_le_bytes([b0, b1, b2, b3])),
            Scalar::F32 => f64::from(f32::from_le_bytes([b0, b1, b2, b3])),
            Scalar::F64 => f64::from_le_bytes(raw),
        })
    }
}

/// Reads every element in header order, keeping vertex positions and face index lists.
fn read_elements(
    path: &Path,
    elements: &[Element],
    values: &mut impl Values,
) -> Result<TriangleMesh, IoError> {
    let vertex = elements
        .iter()
        .find(|e| e.name == "vertex")
        .ok_or_else(|| IoError::invalid(path, "the PLY file has no vertex element"))?;
    for axis in ["x", "y", "z"] {
        if !vertex
            .properties
            .iter()
            .any(|p| matches!(p, Property::Scalar { name, .. } if name == axis))
        {
            return Err(IoError::invalid(
                path,
                format!("the vertex element has no scalar property {axis:?}"),
            ));
        }
    }
    let mut mesh = TriangleMesh::default();
    // An element without properties has nothing to read, however large its count.
    for element in elements.iter().filter(|e| !e.properties.is_empty()) {
        for item in 0..element.count {
            let mut point = [0.0f64; 3];
            let mut face: Vec<f64> = Vec::new();
            for property in &element.properties {
                let what = || format!("{} {item} property {:?}", element.name, property.name());
                match property {
                    Property::Scalar { name, ty } => {
                        let value = values.value(*ty, &what)?;
                        if let Some(axis) = ["x", "y", "z"].iter().position(|a| a == name) {
                            point[axis] = value;
                        }
                    }
                    Property::List { name, count, item } => {
                        let length = values.value(*count, &what)?;
                        if !(0.0..=f64::from(u32::MAX)).contains(&length) || length.fract() != 0.0 {
                            return Err(IoError::invalid(
                                path,
                                format!("{}: bad list length {length}", what()),
                            ));
                        }
                        let list = (0..length as usize)
                            .map(|_| values.value(*item, &what))
                            .collect::<Result<Vec<f64>, IoError>>()?;
                        if name == "vertex_indices" || name == "vertex_index" {
                            face = list;
                        }
                    }
                }
            }
            if element.name == "vertex" {
                let p = Vec3::new(point[0] as f32, point[1] as f32, point[2] as f32);
                if !p.is_finite() {
                    return Err(IoError::invalid(
                        path,
                        format!("vertex {item} has a non-finite position {p}"),
                    ));
                }
                mesh.positions.push(p);
            } else if element.name == "face" {
                push_face(path, item, &face, vertex.count, &mut mesh.triangles)?;
            }
        }
    }
    Ok(mesh)
}

/// Fan-triangulates face `item` after checking its indices against `vertex_count`.
fn push_face(
    path: &Path,
    item: usize,
    face: &[f64],
    vertex_count: usize,
    triangles: &mut Vec<[u32; 3]>,
) -> Result<(), IoError> {
    let context = |message: String| IoError::invalid(path, format!("face {item}: {message}"));
    if face.len() < 3 {
        return Err(context(format!(
            "{} vertices, at least 3 needed",
            face.len()
        )));
    }
    let corners = face
        .iter()
        .map(|&index| {
            let in_range = index >= 0.0 && index < vertex_count.min(u32::MAX as usize) as f64;
            if in_range && index.fract() == 0.0 {
                Ok(index as u32)
            } else {
                Err(context(format!(
                    "vertex index {index} is out of range ({vertex_count} defined)"
                )))
            }
        })
        .collect::<Result<Vec<u32>, IoError>>()?;
    for k in 1..corners.len() - 1 {
        triangles.push([corners[0], corners[k], corners[k + 1]]);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::text::scratch_file;

    const HEADER: &str = "ply\nformat FORMAT 1.0\ncomment test\nelement vertex 4\n\
        property float x\nproperty float y\nproperty float z\nproperty uchar red\n\
        element face 1\nproperty list uchar int vertex_indices\nend_header\n";

    fn binary(big_endian: bool) -> Vec<u8> {
        let format = if big_endian {
            "binary_big_endian"
        } else {
            "binary_little_endian"
        };
        let mut bytes = HEADER.replace("FORMAT", format).into_bytes();
        let points = [
            [0.0f32, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        for p in points {
            for c in p {
                bytes.extend(if big_endian {
                    c.to_be_bytes()
                } else {
                    c.to_le_bytes()
                });
            }
            bytes.push(200);
        }
        bytes.push(4);
        for i in [0i32, 1, 2, 3] {
            bytes.extend(if big_endian {
                i.to_be_bytes()
            } else {
                i.to_le_bytes()
            });
        }
        bytes
    }

    #[test]
    fn ascii_and_both_binary_byte_orders_agree() {
        let ascii =
            HEADER.replace("FORMAT", "ascii") + "0 0 0 1\n1 0 0 1\n1 1 0 1\n0 1 0 1\n4 0 1 2 3\n";
        let expected = read(&scratch_file("a.ply", ascii)).unwrap();
        assert_eq!(expected.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(expected.positions[2], Vec3::new(1.0, 1.0, 0.0));
        assert_eq!(
            read(&scratch_file("le.ply", binary(false))).unwrap(),
            expected
        );
        assert_eq!(
            read(&scratch_file("be.ply", binary(true))).unwrap(),
            expected
        );
    }

    #[test]
    fn broken_files_are_errors() {
        let ascii = |body: &str| HEADER.replace("FORMAT", "ascii") + body;
        let mut truncated = binary(false);
        truncated.truncate(truncated.len() - 3);
        let cases: Vec<(Vec<u8>, &str)> = vec![
            (b"plx\n".to_vec(), ":1: not a PLY file"),
            (b"ply\nformat ascii 1.0\n".to_vec(), "no end_header"),
            (
                HEADER.replace("FORMAT", "ebcdic").into_bytes(),
                ":2: unknown PLY format",
            ),
            (
                ascii("0 0 0 1\n1 0 0 1\n1 1 0 1\n0 1 0 1\n3 0 1 9\n").into_bytes(),
                "face 0: vertex index 9 is out of range",
            ),
            (
                ascii("0 0 0 1\n1 0 0 1\n1 1 0 1\n0 1 0 1\n2 0 1\n").into_bytes(),
                "face 0: 2 vertices",
            ),
            (
                ascii("0 0 nan 1\n").into_bytes(),
                "vertex 0 has a non-finite position",
            ),
            (
                ascii("0 0 0 1\n").into_bytes(),
                ":12: unexpected end of file",
            ),
            (truncated, "the data ends at byte"),
        ];
        for (i, (bytes, expected)) in cases.into_iter().enumerate() {
            let error = read(&scratch_file(&format!("bad{i}.ply"), bytes)).unwrap_err();
            assert!(
                error.to_string().contains(expected),
                "{error} lacks {expected}"
            );
        }
    }
}

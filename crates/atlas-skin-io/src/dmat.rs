//! libigl `.dmat` dense matrices (ASCII or binary), used for per-vertex weights.

use crate::text::{read_bytes, Tokens};
use crate::IoError;
use atlas_skin_runtime::VertexWeights;
use std::path::Path;

/// A dense #rows × #cols matrix, column-major: entry (r, c) is `values[c * rows + r]`.
#[derive(Debug, Clone, PartialEq)]
pub struct DenseMatrix {
    pub rows: usize,
    pub cols: usize,
    pub values: Vec<f64>,
}

/// Reads the `.dmat` at `path`, as libigl's `readDMAT` writes it:
///
/// - ASCII: a `cols rows` line, then cols × rows numbers, column by column;
/// - binary: a `0 0` line, a `cols rows` line, then cols × rows little-endian f64, column
///   by column, and nothing else.
///
/// Non-finite values are errors.
pub fn read(path: &Path) -> Result<DenseMatrix, IoError> {
    let bytes = read_bytes(path)?;
    let (first, rest) = split_line(&bytes);
    let (cols, rows) = parse_size(path, 1, first)?;
    if (cols, rows) == (0, 0) && !rest.is_empty() {
        let (second, data) = split_line(rest);
        let (cols, rows) = parse_size(path, 2, second)?;
        let values = binary_values(path, cols, rows, data)?;
        return Ok(DenseMatrix { rows, cols, values });
    }
    let values = ascii_values(path, cols, rows, rest)?;
    Ok(DenseMatrix { rows, cols, values })
}

/// cols × rows little-endian f64 filling `data` exactly.
fn binary_values(path: &Path, cols: usize, rows: usize, data: &[u8]) -> Result<Vec<f64>, IoError> {
    let expected = cols.checked_mul(rows).and_then(|n| n.checked_mul(8));
    if expected != Some(data.len()) {
        return Err(IoError::invalid(
            path,
            format!(
                "binary DMAT of {cols} columns × {rows} rows needs {} bytes of data, the file has {}",
                cols as u128 * rows as u128 * 8,
                data.len()
            ),
        ));
    }
    let values: Vec<f64> = data
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]))
        .collect();
    match values.iter().position(|v| !v.is_finite()) {
        Some(at) => Err(IoError::invalid(
            path,
            format!("value {at} is {}, not a finite number", values[at]),
        )),
        None => Ok(values),
    }
}

/// cols × rows ASCII numbers after the header line, and nothing else.
fn ascii_values(path: &Path, cols: usize, rows: usize, rest: &[u8]) -> Result<Vec<f64>, IoError> {
    // A leading newline makes the token lines count from the header line.
    let text = format!("\n{}", String::from_utf8_lossy(rest));
    let mut tokens = Tokens::new(path, &text, None);
    let count = cols
        .checked_mul(rows)
        .ok_or_else(|| IoError::invalid(path, "matrix size overflows"))?;
    let mut values = Vec::with_capacity(count.min(1 << 26));
    for _ in 0..count {
        let value: f64 = tokens.parse("matrix value")?;
        if !value.is_finite() {
            return Err(tokens.error(format!("value {value} is not a finite number")));
        }
        values.push(value);
    }
    if tokens.next_token().is_some() {
        return Err(tokens.error(format!(
            "more than the {count} values announced ({cols} × {rows})"
        )));
    }
    Ok(values)
}

/// The bytes up to the first newline, and those after it.
fn split_line(bytes: &[u8]) -> (&[u8], &[u8]) {
    match bytes.iter().position(|&b| b == b'\n') {
        Some(at) => (&bytes[..at], &bytes[at + 1..]),
        None => (bytes, &[]),
    }
}

/// Parses a `cols rows` header line.
fn parse_size(path: &Path, line: usize, bytes: &[u8]) -> Result<(usize, usize), IoError> {
    let text = String::from_utf8_lossy(bytes);
    let mut tokens = text.split_whitespace().map(str::parse::<usize>);
    match (tokens.next(), tokens.next(), tokens.next()) {
        (Some(Ok(cols)), Some(Ok(rows)), None) => Ok((cols, rows)),
        _ => Err(IoError::syntax(
            path,
            line,
            format!("expected \"columns rows\", found {:?}", text.trim()),
        )),
    }
}

impl DenseMatrix {
    /// Per-row weights where column c goes to joint `column_joint[c]`; columns sharing a
    /// joint are summed: `w(v, j) = Σ_{c : column_joint[c] = j} M(v, c)`. Values in
    /// [−1e-3, 0] (solver round-off in libigl's files) are dropped; more negative values
    /// are an error naming the row and column.
    pub fn to_weights(&self, path: &Path, column_joint: &[u32]) -> Result<VertexWeights, IoError> {
        if column_joint.len() != self.cols {
            return Err(IoError::invalid(
                path,
                format!(
                    "{} columns, expected {} (one per bone or joint)",
                    self.cols,
                    column_joint.len()
                ),
            ));
        }
        let mut rows: Vec<Vec<(u32, f32)>> = vec![Vec::new(); self.rows];
        for (c, &joint) in column_joint.iter().enumerate() {
            for (r, &value) in self.values[c * self.rows..(c + 1) * self.rows]
                .iter()
                .enumerate()
            {
                if value < -1e-3 {
                    return Err(IoError::invalid(
                        path,
                        format!("row {r} column {c} has negative weight {value}"),
                    ));
                }
                if value <= 0.0 {
                    continue;
                }
                match rows[r].iter_mut().find(|(j, _)| *j == joint) {
                    Some(entry) => entry.1 += value as f32,
                    None => rows[r].push((joint, value as f32)),
                }
            }
        }
        Ok(VertexWeights::from_rows(rows))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::text::scratch_file;

    #[test]
    fn ascii_and_binary_are_column_major() {
        let ascii = read(&scratch_file("m.dmat", "3 2\n1\n2\n3 4\n5 6\n")).unwrap();
        assert_eq!((ascii.rows, ascii.cols), (2, 3));
        assert_eq!(ascii.values, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        let mut bytes = b"0 0\n3 2\n".to_vec();
        for v in 1..=6 {
            bytes.extend(f64::from(v).to_le_bytes());
        }
        assert_eq!(read(&scratch_file("m-bin.dmat", bytes)).unwrap(), ascii);
    }

    #[test]
    fn columns_sharing_a_joint_are_summed() {
        let matrix = DenseMatrix {
            rows: 2,
            cols: 3,
            values: vec![0.5, 0.0, 0.25, 1.0, 0.25, -1e-9],
        };
        let weights = matrix.to_weights(Path::new("w.dmat"), &[0, 1, 0]).unwrap();
        assert_eq!(weights.row(0).collect::<Vec<_>>(), [(0, 0.75), (1, 0.25)]);
        assert_eq!(weights.row(1).collect::<Vec<_>>(), [(1, 1.0)]);
        assert!(matrix.to_weights(Path::new("w.dmat"), &[0, 1]).is_err());
        let negative = DenseMatrix {
            rows: 1,
            cols: 1,
            values: vec![-0.5],
        };
        let error = negative
            .to_weights(Path::new("w.dmat"), &[0])
            .unwrap_err()
            .to_string();
        assert!(
            error.contains("row 0 column 0 has negative weight -0.5"),
            "{error}"
        );
    }

    #[test]
    fn broken_files_are_errors() {
        let cases: Vec<(Vec<u8>, &str)> = vec![
            (b"3\n1 2 3\n".to_vec(), ":1: expected \"columns rows\""),
            (b"2 2\n1 2\n3\n".to_vec(), ":3: unexpected end of file"),
            (b"1 2\n1 2 3\n".to_vec(), ":2: more than the 2 values"),
            (b"1 1\nnan\n".to_vec(), ":2: value NaN"),
            (
                b"0 0\n1 2\n12345678".to_vec(),
                "needs 16 bytes of data, the file has 8",
            ),
        ];
        for (i, (bytes, expected)) in cases.into_iter().enumerate() {
            let error = read(&scratch_file(&format!("bad{i}.dmat"), bytes)).unwrap_err();
            assert!(
                error.to_string().contains(expected),
                "{error} lacks {expected}"
            );
        }
    }
}

//! A check of ASCII FBX arrays before trusting ufbx's reading of them: ufbx reads a stray
//! word in a number array as a character code (`abc` becomes 97) and ignores a declared
//! count that does not match, so both are caught here with their line.

use crate::IoError;
use std::path::Path;

/// Checks every array block `Name: *N {` … `}` of the ASCII FBX `text`: its values (after
/// `a:`, comma-separated, over any number of lines) must be numbers (`nan` and `inf`
/// included: the reader rejects them where they matter) and there must be exactly N.
///
/// # Errors
/// [`IoError::Syntax`] at the line of the first value that is not a number, or at the
/// line declaring a count the block does not hold.
pub fn check(path: &Path, text: &str) -> Result<(), IoError> {
    // (line of the declaration, declared count, values seen)
    let mut open: Option<(usize, u64, u64)> = None;
    for (index, raw) in text.lines().enumerate() {
        let line = index + 1;
        let content = raw.trim();
        match &mut open {
            None => {
                let Some(declared) = declared_count(content) else {
                    continue;
                };
                open = Some((line, declared, 0));
            }
            Some((start, declared, seen)) => {
                let (values, closes) = match content.strip_suffix('}') {
                    Some(rest) => (rest, true),
                    None => (content, false),
                };
                let values = values.trim_start().strip_prefix("a:").unwrap_or(values);
                for token in values.split(',').map(str::trim).filter(|t| !t.is_empty()) {
                    if token.parse::<f64>().is_err() {
                        return Err(IoError::syntax(
                            path,
                            line,
                            format!("array value {token:?} is not a number"),
                        ));
                    }
                    *seen += 1;
                }
                if closes {
                    if seen != declared {
                        return Err(IoError::syntax(
                            path,
                            *start,
                            format!("the array declares {declared} values but holds {seen}"),
                        ));
                    }
                    open = None;
                }
            }
        }
    }
    Ok(())
}

/// N of a line `Name: *N {` (an array declaration), if it is one.
fn declared_count(line: &str) -> Option<u64> {
    let rest = line.strip_suffix('{')?.trim_end();
    let (_, count) = rest.rsplit_once(": *")?;
    count.parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_over_several_lines_pass_and_bad_values_name_their_line() {
        let path = Path::new("a.fbx");
        let good = "Vertices: *4 {\n a: 1,-2.5e-007,\n3,nan\n}\nName: \"x\"\n";
        check(path, good).unwrap();
        let word = "Vertices: *3 {\n a: 1,abc,3\n}\n";
        let error = check(path, word).unwrap_err().to_string();
        assert!(
            error.contains("a.fbx:2: array value \"abc\" is not a number"),
            "{error}"
        );
        let count = "\nIndexes: *999999999999 {\n a: 1,2\n}\n";
        let error = check(path, count).unwrap_err().to_string();
        assert!(
            error.contains(":2: the array declares 999999999999 values but holds 2"),
            "{error}"
        );
        let one_line = "Indexes: *2 {\n a: 1,2 }\n";
        check(path, one_line).unwrap();
    }
}

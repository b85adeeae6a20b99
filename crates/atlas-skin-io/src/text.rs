//! Reading shared by the text formats: whole files, whitespace-separated tokens with line
//! numbers, numbers with errors that name the file and line, and JSON documents.

use crate::IoError;
use glam::Vec3;
use serde::de::DeserializeOwned;
use std::path::Path;
use std::str::FromStr;

/// Errors for a path that is missing, unreadable, a directory, not a regular file (a
/// device, a FIFO: reading those could block or never end) or an empty file.
pub(crate) fn check_file(path: &Path) -> Result<(), IoError> {
    let metadata = std::fs::metadata(path).map_err(|cause| IoError::Read {
        path: path.to_path_buf(),
        cause,
    })?;
    if metadata.is_dir() {
        return Err(IoError::IsDirectory {
            path: path.to_path_buf(),
        });
    }
    if !metadata.is_file() {
        return Err(IoError::NotARegularFile {
            path: path.to_path_buf(),
        });
    }
    if metadata.len() == 0 {
        return Err(IoError::Empty {
            path: path.to_path_buf(),
        });
    }
    Ok(())
}

/// The bytes of `path` (see [`check_file`]).
pub(crate) fn read_bytes(path: &Path) -> Result<Vec<u8>, IoError> {
    check_file(path)?;
    std::fs::read(path).map_err(|cause| IoError::Read {
        path: path.to_path_buf(),
        cause,
    })
}

/// The text of `path` (see [`read_bytes`]). Bytes that are not UTF-8 become U+FFFD: they
/// only ever occur in comments of the files seen in practice.
pub(crate) fn read_text(path: &Path) -> Result<String, IoError> {
    let bytes = read_bytes(path)?;
    Ok(match String::from_utf8(bytes) {
        Ok(text) => text,
        Err(error) => String::from_utf8_lossy(error.as_bytes()).into_owned(),
    })
}

/// Whether `text` is ASCII without vertical tabs: then [`str::split_ascii_whitespace`]
/// splits it exactly as [`str::split_whitespace`] does (U+000B is the one ASCII character
/// that only the latter takes for a separator), byte by byte instead of char by char.
pub(crate) fn is_plain_ascii(text: &str) -> bool {
    text.is_ascii() && !text.contains('\x0B')
}

/// The whitespace-separated words of a line: split byte by byte when the file is
/// [`is_plain_ascii`], by Unicode whitespace otherwise (the same words).
pub(crate) enum Words<'a> {
    Ascii(std::str::SplitAsciiWhitespace<'a>),
    Unicode(std::str::SplitWhitespace<'a>),
}

impl<'a> Words<'a> {
    pub(crate) fn of(line: &'a str, plain_ascii: bool) -> Self {
        if plain_ascii {
            Self::Ascii(line.split_ascii_whitespace())
        } else {
            Self::Unicode(line.split_whitespace())
        }
    }
}

impl<'a> Iterator for Words<'a> {
    type Item = &'a str;

    fn next(&mut self) -> Option<&'a str> {
        match self {
            Self::Ascii(words) => words.next(),
            Self::Unicode(words) => words.next(),
        }
    }
}

/// The lines of `text` ([`str::lines`]), each cut at its first `comment` character: the
/// same as `line.split(comment).next()` line by line, but the comment characters are
/// found by a search through the text that starts again only at the line after one (a
/// search per line cost about 145 instructions, 8.6 M on makehuman's OBJ of 59,167 lines
/// of which 16 hold a comment).
pub(crate) fn uncommented_lines(text: &str, comment: char) -> impl Iterator<Item = &str> {
    // The first comment character at or after the start of the line before (or of the
    // text).
    let mut next_comment = text.find(comment);
    text.lines().map(move |line| {
        // The line's place in the text, of which it is a slice.
        let start = line.as_ptr() as usize - text.as_ptr() as usize;
        if next_comment.is_some_and(|at| at < start) {
            next_comment = text[start..].find(comment).map(|k| start + k);
        }
        match next_comment {
            Some(at) if at < start + line.len() => &line[..at - start],
            _ => line,
        }
    })
}

/// Parses the JSON document at `path` into `T`; syntax and shape errors carry the line.
pub(crate) fn read_json<T: DeserializeOwned>(path: &Path) -> Result<T, IoError> {
    let text = read_text(path)?;
    serde_json::from_str(&text).map_err(|error| {
        // serde_json appends " at line L column C"; the line goes into the error instead.
        let message = error.to_string();
        let message = match message.rfind(" at line ") {
            Some(at) => message[..at].to_string(),
            None => message,
        };
        IoError::syntax(path, error.line().max(1), message)
    })
}

/// Parses `token` as a `T`, or says which `what` was expected at `line`.
pub(crate) fn parse_field<T: FromStr>(
    path: &Path,
    line: usize,
    token: Option<&str>,
    what: &str,
) -> Result<T, IoError> {
    let token = token.ok_or_else(|| IoError::syntax(path, line, format!("missing {what}")))?;
    token.parse().map_err(|_| {
        IoError::syntax(
            path,
            line,
            format!("{what} {token:?} is not a valid number"),
        )
    })
}

/// Parses `token` as a finite f32 coordinate (NaN and infinities are errors).
pub(crate) fn parse_finite(
    path: &Path,
    line: usize,
    token: Option<&str>,
    what: &str,
) -> Result<f32, IoError> {
    let value: f32 = parse_field(path, line, token, what)?;
    if value.is_finite() {
        Ok(value)
    } else {
        Err(IoError::syntax(
            path,
            line,
            format!("{what} is {value}, not a finite number"),
        ))
    }
}

/// Parses the next three tokens as a finite point.
pub(crate) fn parse_point<'a>(
    path: &Path,
    line: usize,
    tokens: &mut impl Iterator<Item = &'a str>,
) -> Result<Vec3, IoError> {
    let x = parse_finite(path, line, tokens.next(), "x coordinate")?;
    let y = parse_finite(path, line, tokens.next(), "y coordinate")?;
    let z = parse_finite(path, line, tokens.next(), "z coordinate")?;
    Ok(Vec3::new(x, y, z))
}

/// Checks an `index` as written in a file whose first valid index is `first` (0 or 1)
/// against `count` items, and returns it 0-based.
pub(crate) fn check_index(
    path: &Path,
    line: usize,
    index: i64,
    first: i64,
    count: usize,
    what: &str,
) -> Result<u32, IoError> {
    let zero_based = index - first;
    if zero_based >= 0 && (zero_based as u64) < count as u64 && zero_based < i64::from(u32::MAX) {
        Ok(zero_based as u32)
    } else {
        Err(IoError::syntax(
            path,
            line,
            format!("{what} index {index} is out of range ({count} defined)"),
        ))
    }
}

/// Whitespace-separated tokens of a text file with the line each came from, skipping
/// comments that start with `comment`.
pub(crate) struct Tokens<'a> {
    path: &'a Path,
    lines: std::iter::Enumerate<std::str::Lines<'a>>,
    current: std::str::SplitWhitespace<'a>,
    line: usize,
    comment: Option<char>,
}

impl<'a> Tokens<'a> {
    pub(crate) fn new(path: &'a Path, text: &'a str, comment: Option<char>) -> Self {
        Self {
            path,
            lines: text.lines().enumerate(),
            current: "".split_whitespace(),
            line: 0,
            comment,
        }
    }

    /// The file being read.
    pub(crate) fn path(&self) -> &'a Path {
        self.path
    }

    /// 1-based line of the last token returned.
    pub(crate) fn line(&self) -> usize {
        self.line
    }

    /// A syntax error at the current line.
    pub(crate) fn error(&self, message: impl Into<String>) -> IoError {
        IoError::syntax(self.path, self.line.max(1), message)
    }

    /// The next token, `None` at the end of the file.
    pub(crate) fn next_token(&mut self) -> Option<&'a str> {
        loop {
            if let Some(token) = self.current.next() {
                return Some(token);
            }
            let (index, line) = self.lines.next()?;
            self.line = index + 1;
            let content = match self.comment.and_then(|c| line.find(c)) {
                Some(at) => &line[..at],
                None => line,
            };
            self.current = content.split_whitespace();
        }
    }

    /// The next token, or an error naming the `what` that was expected.
    pub(crate) fn word(&mut self, what: &str) -> Result<&'a str, IoError> {
        self.next_token()
            .ok_or_else(|| self.error(format!("unexpected end of file, expected {what}")))
    }

    /// The next token parsed as a `T`.
    pub(crate) fn parse<T: FromStr>(&mut self, what: &str) -> Result<T, IoError> {
        let token = self.word(what)?;
        parse_field(self.path, self.line, Some(token), what)
    }

    /// The next token as a finite f32.
    pub(crate) fn finite(&mut self, what: &str) -> Result<f32, IoError> {
        let token = self.word(what)?;
        parse_finite(self.path, self.line, Some(token), what)
    }

    /// The next three tokens as a finite point.
    pub(crate) fn point(&mut self) -> Result<Vec3, IoError> {
        Ok(Vec3::new(
            self.finite("x coordinate")?,
            self.finite("y coordinate")?,
            self.finite("z coordinate")?,
        ))
    }

    /// The next token, which must be `keyword` (compared without case).
    pub(crate) fn expect(&mut self, keyword: &str) -> Result<(), IoError> {
        let token = self.word(keyword)?;
        if token.eq_ignore_ascii_case(keyword) {
            Ok(())
        } else {
            Err(self.error(format!("expected {keyword:?}, found {token:?}")))
        }
    }
}

/// Writes `contents` to a fresh file `name` in this process's scratch folder (unit tests).
#[cfg(test)]
pub(crate) fn scratch_file(name: &str, contents: impl AsRef<[u8]>) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("atlas-skin-io-unit-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch folder");
    let path = dir.join(name);
    std::fs::write(&path, contents).expect("scratch file");
    path
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_skip_comments_and_track_lines() {
        let path = Path::new("t.txt");
        let mut tokens = Tokens::new(path, "a # b c\n\n  1.5 nan\n", Some('#'));
        assert_eq!(tokens.word("a").unwrap(), "a");
        assert_eq!(tokens.line(), 1);
        assert_eq!(tokens.finite("x").unwrap(), 1.5);
        assert_eq!(tokens.line(), 3);
        let error = tokens.finite("y").unwrap_err().to_string();
        assert!(
            error.starts_with("t.txt:3:") && error.contains("not a finite"),
            "{error}"
        );
        let error = tokens.word("z").unwrap_err().to_string();
        assert!(
            error.contains("unexpected end of file, expected z"),
            "{error}"
        );
    }

    /// Lines cut at their comments as line by line: comments at the start, in the middle
    /// and at the end of lines, several on a line and on consecutive lines, empty lines,
    /// "\r\n" endings, a last line without an ending, other characters and a text without
    /// comments.
    #[test]
    fn uncommented_lines_are_the_lines_cut_one_by_one() {
        let texts = [
            "",
            "#",
            "\n\n#\n",
            "v 1 2 3\nf 1 2 3",
            "# header ## more\n#\nv 1 2 3 # tail\r\nv 4#5 6\n\nf 1/1 2/2 3/3#\n# last",
            "é #ü\r\n\r\nß#\n##\n x",
        ];
        for text in texts {
            for comment in ['#', 'ü', '/'] {
                let expected: Vec<&str> = text
                    .lines()
                    .map(|line| line.split(comment).next().unwrap_or_default())
                    .collect();
                let found: Vec<&str> = uncommented_lines(text, comment).collect();
                assert_eq!(found, expected, "{text:?} cut at {comment:?}");
            }
        }
    }

    #[test]
    fn ascii_words_are_the_unicode_words_of_plain_ascii() {
        let line = " v\t1.5  -2\x0C3\r f 1/2/3 ";
        assert!(is_plain_ascii(line));
        let ascii: Vec<&str> = Words::of(line, true).collect();
        assert_eq!(ascii, line.split_whitespace().collect::<Vec<_>>());
        assert_eq!(ascii, ["v", "1.5", "-2", "3", "f", "1/2/3"]);
        // A vertical tab or a non-ASCII space separates only as Unicode whitespace.
        for line in ["1\x0B2", "1\u{A0}2"] {
            assert!(!is_plain_ascii(line));
            assert_eq!(Words::of(line, false).collect::<Vec<_>>(), ["1", "2"]);
        }
    }

    #[test]
    fn fields_and_indices_report_their_line() {
        let path = Path::new("f.obj");
        let error = parse_field::<u32>(path, 7, Some("x1"), "index").unwrap_err();
        assert_eq!(
            error.to_string(),
            "f.obj:7: index \"x1\" is not a valid number"
        );
        let error = check_index(path, 2, 4, 1, 3, "vertex")
            .unwrap_err()
            .to_string();
        assert_eq!(error, "f.obj:2: vertex index 4 is out of range (3 defined)");
        assert!(check_index(path, 2, 0, 1, 3, "vertex").is_err());
        assert_eq!(check_index(path, 2, 3, 1, 3, "vertex").unwrap(), 2);
        assert_eq!(check_index(path, 2, 0, 0, 3, "vertex").unwrap(), 0);
        let mut tokens = "1 2".split_whitespace();
        assert!(parse_point(path, 1, &mut tokens)
            .unwrap_err()
            .to_string()
            .contains("missing z"));
    }
}

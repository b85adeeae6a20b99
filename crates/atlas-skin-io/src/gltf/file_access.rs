//! Which files a glTF document may make the reader open: the policy for the `uri` of
//! buffers and images (docs/formats.md, "Files a glTF may name").
//!
//! A `uri` is a `data:` URI or a relative reference to a regular file inside the folder of
//! the document, after percent-decoding, `..` and symbolic links are resolved. Every file
//! is read at most once and never past a size given by the caller, so a document cannot
//! copy a file from elsewhere into an output, read a device or FIFO, or read one large file
//! many times.

use base64::Engine;
use std::collections::HashMap;
use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};

/// The files a document has read so far, and the folder they must lie in.
pub(crate) struct DocumentFolder {
    /// The document's folder, with links resolved; `None` when it cannot be resolved (then
    /// no file can be read).
    folder: Option<PathBuf>,
    shown: PathBuf,
    /// Each file read, by resolved path, with what read it (e.g. `buffers[1]`).
    read: HashMap<PathBuf, String>,
}

/// The bytes a `uri` gave and the media type a `data:` URI declares.
pub(crate) struct UriBytes {
    pub bytes: Vec<u8>,
    pub media_type: Option<String>,
}

impl DocumentFolder {
    /// The folder of the document at `document`.
    pub fn of(document: &Path) -> Self {
        let shown = match document.parent() {
            Some(folder) if !folder.as_os_str().is_empty() => folder.to_path_buf(),
            _ => PathBuf::from("."),
        };
        Self {
            folder: shown.canonicalize().ok(),
            shown,
            read: HashMap::new(),
        }
    }

    /// The bytes `uri` names, for the JSON item `user` (e.g. `buffers[2]`), at most
    /// `max_bytes` of them: a longer file is an error unless `take_prefix` (buffers read
    /// their first `byteLength` bytes; an image must fit whole).
    ///
    /// # Errors
    /// A message naming the `uri`: a URI scheme other than `data:`, an absolute path, a
    /// path that leaves the folder (after `..` and links), a file that is not a regular
    /// file, a file already read for another item, a file larger than `max_bytes` (without
    /// `take_prefix`), or a read error.
    pub fn read(
        &mut self,
        uri: &str,
        user: &str,
        max_bytes: u64,
        take_prefix: bool,
    ) -> Result<UriBytes, String> {
        if let Some(data) = uri.strip_prefix("data:") {
            // A data: URI is part of the JSON, already in memory: a buffer may hold more
            // than its byteLength, which is cut off.
            return decode_data_uri(data, if take_prefix { u64::MAX } else { max_bytes });
        }
        let file = self.resolve(uri)?;
        if let Some(first) = self.read.get(&file) {
            return Err(format!(
                "uri {uri:?} names {}, which {first} already read (a file is read once)",
                file.display()
            ));
        }
        let metadata = std::fs::metadata(&file)
            .map_err(|e| format!("uri {uri:?}: cannot read {}: {e}", file.display()))?;
        if !metadata.is_file() {
            return Err(format!(
                "uri {uri:?} names {}, which is not a regular file",
                file.display()
            ));
        }
        if metadata.len() > max_bytes && !take_prefix {
            return Err(format!(
                "uri {uri:?}: {} has {} bytes, more than the {max_bytes} allowed",
                file.display(),
                metadata.len()
            ));
        }
        let bytes = read_at_most(&file, max_bytes)
            .map_err(|e| format!("uri {uri:?}: cannot read {}: {e}", file.display()))?;
        self.read.insert(file, user.to_string());
        Ok(UriBytes {
            bytes,
            media_type: None,
        })
    }

    /// The file a relative `uri` names, resolved and checked to lie inside the folder.
    fn resolve(&self, uri: &str) -> Result<PathBuf, String> {
        if has_scheme(uri) {
            return Err(format!(
                "uri {uri:?} is not a data: URI nor a relative path (only files beside the \
                 document are read)"
            ));
        }
        let relative = percent_decode(uri)?;
        if relative.starts_with('/') || relative.starts_with('\\') {
            return Err(format!(
                "uri {uri:?} is an absolute path (only files beside the document are read)"
            ));
        }
        let folder = self.folder.as_ref().ok_or_else(|| {
            format!(
                "uri {uri:?}: the document's folder {} cannot be resolved",
                self.shown.display()
            )
        })?;
        let joined = folder.join(&relative);
        let file = joined
            .canonicalize()
            .map_err(|e| format!("uri {uri:?}: cannot read {}: {e}", joined.display()))?;
        if !file.starts_with(folder) {
            return Err(format!(
                "uri {uri:?} leads to {}, outside the document's folder {} (only files \
                 beside the document are read)",
                file.display(),
                self.shown.display()
            ));
        }
        Ok(file)
    }
}

/// True when `uri` starts with a URI scheme (`scheme:`, RFC 3986 §3.1), a Windows drive
/// letter included.
fn has_scheme(uri: &str) -> bool {
    let Some((scheme, _)) = uri.split_once(':') else {
        return false;
    };
    let mut chars = scheme.chars();
    chars.next().is_some_and(|c| c.is_ascii_alphabetic())
        && chars.all(|c| c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '.'))
}

/// At most `limit` bytes from the start of the regular file `file`.
fn read_at_most(file: &Path, limit: u64) -> std::io::Result<Vec<u8>> {
    let handle = File::open(file)?;
    if !handle.metadata()?.is_file() {
        return Err(std::io::Error::other("not a regular file"));
    }
    let mut bytes = Vec::new();
    handle.take(limit).read_to_end(&mut bytes)?;
    Ok(bytes)
}

/// The bytes of a base64 `data:` URI (the part after `data:`), at most `max_bytes`.
fn decode_data_uri(data: &str, max_bytes: u64) -> Result<UriBytes, String> {
    let (header, payload) = data.split_once(',').ok_or("a data: URI without a comma")?;
    let media_type = header.strip_suffix(";base64").ok_or_else(|| {
        format!("data: URI with header {header:?} is not base64 (only base64 is supported)")
    })?;
    let payload = payload.trim();
    // 4 base64 characters hold 3 bytes.
    let decoded_length = payload.len() as u64 / 4 * 3;
    if decoded_length > max_bytes.saturating_add(3) {
        return Err(format!(
            "data: URI of about {decoded_length} bytes, more than the {max_bytes} allowed"
        ));
    }
    let bytes = base64::engine::general_purpose::STANDARD
        .decode(payload)
        .map_err(|e| format!("bad base64 in data: URI: {e}"))?;
    Ok(UriBytes {
        bytes,
        media_type: (!media_type.is_empty()).then(|| media_type.to_string()),
    })
}

/// Decodes `%XX` escapes of a URI path (RFC 3986 §2.1).
fn percent_decode(uri: &str) -> Result<String, String> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = bytes
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .ok_or_else(|| format!("bad percent escape in uri {uri:?}"))?;
            out.push(hex);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).map_err(|_| format!("uri {uri:?} does not decode to UTF-8"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percent_escapes_decode() {
        assert_eq!(percent_decode("a%20b.bin").unwrap(), "a b.bin");
        assert!(percent_decode("a%2").is_err());
    }

    #[test]
    fn schemes_are_recognised() {
        for uri in [
            "file:/etc/passwd",
            "http://x/y.bin",
            "C:/x.bin",
            "a+b.c-d:x",
        ] {
            assert!(has_scheme(uri), "{uri}");
        }
        for uri in ["a.bin", "sub/a.bin", "./a:b.bin", ":x", "1a:b"] {
            assert!(!has_scheme(uri), "{uri}");
        }
    }

    #[test]
    fn data_uris_decode_within_their_limit() {
        let uri = "application/octet-stream;base64,AAECAw==";
        assert_eq!(decode_data_uri(uri, 4).unwrap().bytes, vec![0, 1, 2, 3]);
        assert!(decode_data_uri("x;base64,AAECAwQFBgcICQ==", 4).is_err());
        assert!(decode_data_uri("x,plain", 100).is_err());
    }
}

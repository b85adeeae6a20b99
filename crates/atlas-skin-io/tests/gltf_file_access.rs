//! The glTF file-access policy (docs/formats.md, "Files a glTF may name"): a buffer `uri`
//! outside the document's folder (by `..`, an absolute path, percent-encoding or a link),
//! naming a FIFO, or naming a file another buffer read is an error naming the `uri`; an
//! image `uri` of that kind is left out with a warning, and none of its bytes reach the
//! skinned output.

mod gltf_support;

use atlas_skin_io::gltf::{self, WriteOptions};
use gltf_support::{assert_valid, out_dir, simpleskin};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// A folder `test/doc` holding `buffer.bin` (SimpleSkin's buffer) and a secret file beside
/// it, `test/secret.bin`; returns (the doc folder, the JSON pointing at buffer.bin).
fn document_folder(test: &str) -> (PathBuf, Value) {
    let root = out_dir(test);
    let doc = root.join("doc");
    std::fs::create_dir_all(&doc).unwrap();
    let (mut json, buffer0) = simpleskin();
    std::fs::write(doc.join("buffer.bin"), &buffer0).unwrap();
    std::fs::write(root.join("secret.bin"), &buffer0).unwrap();
    json["buffers"][0]["uri"] = json!("buffer.bin");
    (doc, json)
}

fn write_json(path: &Path, json: &Value) {
    std::fs::write(path, json.to_string()).unwrap();
}

/// The reader's error for the document `json` written as `doc/name.gltf`.
fn error_of(doc: &Path, name: &str, json: &Value) -> String {
    let path = doc.join(name);
    write_json(&path, json);
    match gltf::read(&path) {
        Ok(_) => panic!("{name}: read without error"),
        Err(error) => error.to_string(),
    }
}

#[test]
fn buffers_outside_the_folder_are_refused() {
    let (doc, json) = document_folder("buffers_outside");
    let secret = doc.parent().unwrap().join("secret.bin");
    std::os::unix::fs::symlink(&secret, doc.join("link.bin")).unwrap();
    let cases = [
        (
            "dotdot",
            "../secret.bin".to_string(),
            "outside the document's folder",
        ),
        ("absolute", secret.display().to_string(), "absolute path"),
        (
            "percent",
            "%2E%2E%2Fsecret.bin".to_string(),
            "outside the document's folder",
        ),
        (
            "link",
            "link.bin".to_string(),
            "outside the document's folder",
        ),
        (
            "scheme",
            "file:///etc/passwd".to_string(),
            "not a data: URI",
        ),
        (
            "dev",
            "../../../../../../../dev/zero".to_string(),
            "outside",
        ),
    ];
    for (name, uri, expected) in cases {
        let mut bad = json.clone();
        bad["buffers"][0]["uri"] = json!(uri);
        let message = error_of(&doc, &format!("{name}.gltf"), &bad);
        assert!(message.contains(expected), "{name}: {message}");
        assert!(message.contains("buffers[0]"), "{name}: {message}");
        assert!(message.contains(&format!("{uri:?}")), "{name}: {message}");
    }
    // The same document reading its own folder's file is fine.
    let good = doc.join("good.gltf");
    write_json(&good, &json);
    gltf::read(&good).unwrap();
}

#[test]
fn fifos_and_second_reads_are_refused() {
    let (doc, json) = document_folder("buffers_fifo");
    let fifo = doc.join("pipe.bin");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap();
    assert!(made.success());
    let mut bad = json.clone();
    bad["buffers"][0]["uri"] = json!("pipe.bin");
    let message = error_of(&doc, "fifo.gltf", &bad);
    assert!(message.contains("not a regular file"), "{message}");

    let mut twice = json.clone();
    let buffers = twice["buffers"].as_array_mut().unwrap();
    let second = format!("buffers[{}]", buffers.len());
    buffers.push(buffers[0].clone());
    let message = error_of(&doc, "twice.gltf", &twice);
    assert!(message.contains(&second), "{message}");
    assert!(message.contains("buffers[0] already read"), "{message}");
}

#[test]
fn a_buffer_is_read_only_up_to_its_byte_length() {
    let (doc, mut json) = document_folder("buffers_long");
    let mut long = std::fs::read(doc.join("buffer.bin")).unwrap();
    long.resize(long.len() + 1000, 0xAB);
    std::fs::write(doc.join("long.bin"), &long).unwrap();
    json["buffers"][0]["uri"] = json!("long.bin");
    let path = doc.join("long.gltf");
    write_json(&path, &json);
    let character = gltf::read(&path).unwrap();
    let declared = json["buffers"][0]["byteLength"].as_u64().unwrap() as usize;
    assert_eq!(character.gltf.unwrap().buffers[0].len(), declared);
}

/// CRC-32 (ISO 3309, the polynomial 0xEDB88320 reflected), as PNG chunks need.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &byte in bytes {
        crc ^= byte as u32;
        for _ in 0..8 {
            crc = if crc & 1 == 1 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

/// A valid 1×1 grey PNG carrying `marker` in a tEXt chunk.
fn png_with_marker(marker: &[u8]) -> Vec<u8> {
    let mut bytes = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut chunk = |kind: &[u8; 4], data: &[u8]| {
        bytes.extend_from_slice(&(data.len() as u32).to_be_bytes());
        let typed: Vec<u8> = kind.iter().chain(data).copied().collect();
        bytes.extend_from_slice(&typed);
        bytes.extend_from_slice(&crc32(&typed).to_be_bytes());
    };
    chunk(b"IHDR", &[0, 0, 0, 1, 0, 0, 0, 1, 8, 0, 0, 0, 0]);
    let text: Vec<u8> = b"Comment\0".iter().chain(marker).copied().collect();
    chunk(b"tEXt", &text);
    // zlib, one stored block holding the scanline [filter 0, grey 0], then its Adler-32.
    chunk(b"IDAT", &[0x78, 1, 1, 2, 0, 0xFD, 0xFF, 0, 0, 0, 2, 0, 1]);
    chunk(b"IEND", &[]);
    bytes
}

#[test]
fn images_outside_the_folder_are_left_out_with_a_warning() {
    let (doc, mut json) = document_folder("images_outside");
    let secret_marker = b"SECRET-IMAGE-BYTES-0123456789";
    let kept_marker = b"KEPT-IMAGE-BYTES-9876543210";
    std::fs::write(
        doc.parent().unwrap().join("secret.png"),
        png_with_marker(secret_marker),
    )
    .unwrap();
    std::fs::write(doc.join("kept.png"), png_with_marker(kept_marker)).unwrap();
    json["images"] = json!([{"uri": "../secret.png"}, {"uri": "kept.png"}]);
    json["textures"] = json!([{"source": 0}, {"source": 1}]);
    let path = doc.join("images.gltf");
    write_json(&path, &json);
    let character = gltf::read(&path).unwrap();
    let warning = character
        .warnings
        .iter()
        .find(|w| w.starts_with("images[0] left out"))
        .unwrap_or_else(|| panic!("no warning: {:?}", character.warnings));
    assert!(warning.contains("\"../secret.png\""), "{warning}");

    let weights = character.reference_weights.clone().unwrap();
    let out = doc.parent().unwrap().join("out.glb");
    gltf::write_skinned_glb(&character, &weights, &WriteOptions::default(), &out).unwrap();
    let bytes = std::fs::read(&out).unwrap();
    let contains = |marker: &[u8]| bytes.windows(marker.len()).any(|w| w == marker);
    assert!(
        !contains(secret_marker),
        "the secret image reached the output"
    );
    assert!(
        contains(kept_marker),
        "the image beside the document is embedded"
    );
    let written = gltf::read(&out).unwrap().gltf.unwrap().document;
    assert_eq!(written["images"].as_array().unwrap().len(), 1);
    assert_eq!(written["textures"], json!([{}, {"source": 0}]));
    assert_valid(&[out]);
}

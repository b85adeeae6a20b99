//! Fuzz target: the fbx reader on arbitrary bytes (errors are fine, panics are bugs).
#![no_main]

use atlas_skin_io::fuzz_input::{read_bytes, Format};

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = read_bytes(Format::Fbx, data);
});

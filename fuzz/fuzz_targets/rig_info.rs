//! Fuzz target: the rig_info reader on arbitrary bytes (errors are fine, panics are bugs).
#![no_main]

use atlas_skin_io::fuzz_input::{read_bytes, Format};

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = read_bytes(Format::RigInfo, data);
});

//! Truncations and random bit flips of the corpus's FBX files (binary and ASCII) and of a
//! RigNet rig_info file: the readers return an error naming the file, or a character; they
//! never panic (ufbx, the C parser under the FBX reader, is fuzzed upstream too).

use atlas_skin_corpus::{damaged_copies, data_file};
use atlas_skin_io::{load_character, LoadOptions};
use std::path::Path;

fn out_dir(test: &str) -> std::path::PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(test);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn damaged_fbx_files_never_panic() {
    let dir = out_dir("fbx-fuzz");
    let mut errors = 0;
    let mut checked = 0;
    for (file, name) in [
        ("fbx/KayKit_Knight.fbx", "binary.fbx"),
        ("fbx/Skeleton_heaps_ascii.fbx", "ascii.fbx"),
        ("fbx/assimp_huesitos.fbx", "small.fbx"),
    ] {
        let original = std::fs::read(data_file(file)).unwrap();
        let path = dir.join(name);
        for bytes in damaged_copies(&original, 150, 250, 1134) {
            std::fs::write(&path, &bytes).unwrap();
            if let Err(error) = load_character(&path, &LoadOptions::default()) {
                assert!(error.to_string().contains(name), "{error}");
                errors += 1;
            }
            checked += 1;
        }
    }
    assert!(
        checked > 1000 && errors > 300,
        "{checked} files, {errors} errors"
    );
}

#[test]
fn damaged_rig_info_files_never_panic() {
    let dir = out_dir("rig-info-fuzz");
    let obj = data_file("rignet-format/498.obj");
    let original = std::fs::read(data_file("rignet-format/498_rig.txt")).unwrap();
    let path = dir.join("damaged_rig.txt");
    let options = LoadOptions {
        skeleton: Some(path.clone()),
        ..LoadOptions::default()
    };
    let mut errors = 0;
    let copies = damaged_copies(&original, 300, 500, 498);
    for bytes in &copies {
        std::fs::write(&path, bytes).unwrap();
        if let Err(error) = load_character(&obj, &options) {
            assert!(error.to_string().contains("damaged_rig.txt"), "{error}");
            errors += 1;
        }
    }
    assert!(
        errors > copies.len() / 2,
        "{errors} errors of {}",
        copies.len()
    );
}

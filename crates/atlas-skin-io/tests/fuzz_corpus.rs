//! The fuzz corpora and crash inputs (`fuzz/corpus/TARGET`, `fuzz/artifacts/TARGET`, kept
//! by `scripts/fuzz`) replayed under the stable toolchain: every file through the reader of
//! its target, which must return (an error is fine) and never panic. The hand-made seeds
//! (`seed-*`) must read without error, so that the fuzzer starts from valid files.

use atlas_skin_io::fuzz_input::{read_bytes, Format};
use std::path::{Path, PathBuf};

fn fuzz_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz")
}

/// The files of `dir`, sorted; none when it does not exist.
fn files_in(dir: &Path) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut files: Vec<PathBuf> = entries
        .map(|e| e.expect("a readable folder entry").path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    files
}

#[test]
fn every_corpus_and_crash_input_reads_without_panic() {
    let mut replayed = 0;
    for format in Format::ALL {
        let corpus = fuzz_dir().join("corpus").join(format.name());
        let seeds = files_in(&corpus)
            .into_iter()
            .filter(|p| {
                p.file_name()
                    .is_some_and(|n| n.to_string_lossy().starts_with("seed-"))
            })
            .count();
        assert!(seeds > 0, "{}: no seed-* file", corpus.display());
        let artifacts = fuzz_dir().join("artifacts").join(format.name());
        for file in files_in(&corpus).into_iter().chain(files_in(&artifacts)) {
            let bytes = std::fs::read(&file).unwrap();
            let result = std::panic::catch_unwind(|| read_bytes(format, &bytes));
            let Ok(result) = result else {
                panic!("{}: the {} reader panicked", file.display(), format.name());
            };
            let is_seed = file
                .file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with("seed-"));
            if let (true, Err(error)) = (is_seed, &result) {
                panic!("seed {} does not read: {error}", file.display());
            }
            replayed += 1;
        }
        let _ = std::fs::remove_dir_all(atlas_skin_io::fuzz_input::scratch_folder(format));
    }
    println!("{replayed} inputs replayed");
}

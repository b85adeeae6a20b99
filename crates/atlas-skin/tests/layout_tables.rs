//! The layout tables of the documentation match the tree: the tables of crates in README.md
//! and docs/README.md list every crate of `crates/` and nothing else, and docs/method.md's table of the
//! method crate's folders lists every top-level module of `crates/atlas-skin/src` and
//! nothing else (the order of that table is checked against the imports by
//! `module_cycles.rs`, through `lib.rs`'s table).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

fn repository() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()))
}

/// The first column of every row of the Markdown table that follows the line `heading`
/// (header and separator skipped), with the backticks removed.
fn first_column_after(text: &str, heading: &str) -> Vec<String> {
    let start = text
        .lines()
        .position(|line| line.trim() == heading)
        .unwrap_or_else(|| panic!("no line `{heading}`"));
    text.lines()
        .skip(start + 1)
        .skip_while(|line| !line.starts_with('|'))
        .take_while(|line| line.starts_with('|'))
        .skip(2)
        .map(|row| row.split('|').nth(1).unwrap().trim().to_string())
        .collect()
}

/// The names between backticks in a cell (`` `a.rs`, `b/` `` gives `a.rs`, `b/`).
fn quoted(cell: &str) -> Vec<String> {
    cell.split('`')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

#[test]
fn the_readmes_list_every_crate() {
    let root = repository();
    let crates: BTreeSet<String> = std::fs::read_dir(root.join("crates"))
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|dir| dir.join("Cargo.toml").is_file())
        .map(|dir| format!("crates/{}", dir.file_name().unwrap().to_string_lossy()))
        .collect();
    for (file, heading) in [
        ("README.md", "## Layout"),
        ("docs/README.md", "## The repository"),
    ] {
        let listed: BTreeSet<String> = first_column_after(&read(&root.join(file)), heading)
            .iter()
            .flat_map(|cell| quoted(cell))
            .collect();
        assert_eq!(
            listed, crates,
            "{file}'s table under `{heading}` against the crates of crates/"
        );
    }
}

#[test]
fn docs_method_lists_every_module_of_the_method_crate() {
    let root = repository();
    let src = root.join("crates/atlas-skin/src");
    let listed: BTreeSet<String> = first_column_after(
        &read(&root.join("docs/method.md")),
        "## The method crate's folders",
    )
    .iter()
    .flat_map(|cell| quoted(cell))
    .filter(|name| name != "crates/atlas-skin/src/")
    .collect();
    let modules: BTreeSet<String> = std::fs::read_dir(&src)
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter_map(|path| {
            let name = path.file_name()?.to_string_lossy().into_owned();
            if path.join("mod.rs").is_file() {
                Some(format!("{name}/"))
            } else if name.ends_with(".rs") && name != "lib.rs" {
                Some(name)
            } else {
                None
            }
        })
        .collect();
    assert_eq!(
        listed, modules,
        "docs/method.md's table of the method crate's folders against crates/atlas-skin/src"
    );
}

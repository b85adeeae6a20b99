//! The hostile corpus (issue 18): files and commands an attacker or a careless user would
//! try, each run as its own `atlas-skin` process under `ulimit -v` 2 GB and a 10 s limit.
//!
//! Every case must exit with a clear error (exit 1 or clap's 2, `error:` on stderr and the
//! expected fragment) or succeed with valid outputs (glb outputs pass the Khronos
//! validator); never panic, abort or hang. After every case: no byte of the secret file
//! outside the input's folder appears in any file, and every file that existed before,
//! other than the case's named outputs, is unchanged (SHA-free: compared byte for byte
//! with a copy taken before the run); no other file appeared.

mod support;

use atlas_skin_corpus::{node_check, RIGGEDSIMPLE, SIMPLESKIN};
use serde_json::{json, Value};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use support::out_dir;

/// The virtual memory limit of every case, in KiB (`ulimit -v`).
const MEMORY_LIMIT_KIB: u64 = 2 * 1024 * 1024;
/// The time limit of every case, in seconds.
const TIME_LIMIT_SECONDS: u64 = 10;
/// Bytes of the secret file beside the input's folder, which no output may contain.
const SECRET: &[u8] = b"SECRET-0f3c9a71-outside-the-input-folder";

/// What a case must do.
enum Expect {
    /// Exit non-zero with `error:` and this fragment on stderr.
    Error(&'static str),
    /// Exit 0; these named outputs must exist.
    Success,
}

/// One case: files to create in `doc/` (a name and how to make it), the command line
/// (split at spaces; `{doc}`, `{case}` and `{secret}` are replaced by the input folder, the case folder and
/// the secret file), the outputs it may write (relative to the case folder), what it
/// must do.
struct Case {
    name: &'static str,
    files: Vec<(&'static str, Source)>,
    args: &'static str,
    outputs: Vec<&'static str>,
    expect: Expect,
}

/// How a case file is made.
enum Source {
    Bytes(Vec<u8>),
    /// A symbolic link to this target (placeholders replaced).
    Link(&'static str),
    Fifo,
}

fn simpleskin_json() -> (Value, Vec<u8>) {
    use base64::Engine;
    let text = std::fs::read(SIMPLESKIN.input_path()).unwrap();
    let json: Value = serde_json::from_slice(&text).unwrap();
    let uri = json["buffers"][0]["uri"].as_str().unwrap();
    let buffer = base64::engine::general_purpose::STANDARD
        .decode(uri.split_once(',').unwrap().1)
        .unwrap();
    (json, buffer)
}

/// SimpleSkin with its buffer in `buffer.bin` and `edit` applied: the files of a case.
fn simpleskin_case(edit: impl Fn(&mut Value)) -> Vec<(&'static str, Source)> {
    let (mut json, buffer) = simpleskin_json();
    json["buffers"][0]["uri"] = json!("buffer.bin");
    edit(&mut json);
    vec![
        ("in.gltf", Source::Bytes(json.to_string().into_bytes())),
        ("buffer.bin", Source::Bytes(buffer)),
    ]
}

/// `files` and one more.
fn plus(
    mut files: Vec<(&'static str, Source)>,
    name: &'static str,
    source: Source,
) -> Vec<(&'static str, Source)> {
    files.push((name, source));
    files
}

/// The case `name` that runs [`SKIN`] on `files` and may write `out.glb`.
fn skin_case(name: &'static str, files: Vec<(&'static str, Source)>, expect: Expect) -> Case {
    Case {
        name,
        files,
        args: SKIN,
        outputs: vec!["out.glb"],
        expect,
    }
}

fn riggedsimple() -> Vec<(&'static str, Source)> {
    vec![(
        "in.glb",
        Source::Bytes(std::fs::read(RIGGEDSIMPLE.input_path()).unwrap()),
    )]
}

/// Skins the case's `in.gltf`.
const SKIN: &str = "skin {doc}/in.gltf -o {case}/out.glb";

/// Careless commands on RiggedSimple (`doc/in.glb`): (name, arguments split at spaces,
/// the error's fragment). None may write anything.
const CARELESS: &[(&str, &str, &str)] = &[
    (
        "output-is-input",
        "skin {doc}/in.glb -o {doc}/in.glb",
        "refusing to write over the input file",
    ),
    (
        "html-is-input",
        "skin {doc}/in.glb -o {case}/o.glb --html {doc}/./in.glb",
        "refusing to write over the input file",
    ),
    (
        "debug-is-input",
        "skin {doc}/in.glb -o {case}/o.glb --debug-glb {doc}/in.glb",
        "refusing to write over the input file",
    ),
    (
        "two-outputs-one-file",
        "skin {doc}/in.glb -o {case}/o.glb --debug-glb {case}/o.glb",
        "cannot write it twice",
    ),
    (
        "pose-output-is-input",
        "pose {doc}/in.glb --random 1 -o {doc}/in.glb",
        "refusing to write over the input file",
    ),
    (
        "output-is-a-device",
        "skin {doc}/in.glb -o /dev/null",
        "not a regular file",
    ),
    (
        "output-is-a-folder",
        "skin {doc}/in.glb -o {doc}",
        "is a directory",
    ),
    (
        "max-influences-huge",
        "skin {doc}/in.glb -o {case}/o.glb --max-influences 4294967296",
        "outside 1..=32",
    ),
    (
        "eval-poses-huge",
        "eval {doc}/in.glb {doc}/in.glb --poses 1000000000",
        "outside 1..=10000",
    ),
    (
        "bench-vertices-huge",
        "bench {doc}/in.glb --vertices 4000000000",
        "outside 1..=10000000",
    ),
    (
        "bench-threads-huge",
        "bench {doc}/in.glb --threads 100000",
        "outside 1..=256",
    ),
    (
        "input-is-a-device",
        "inspect /dev/zero",
        "not a regular file",
    ),
];

fn cases() -> Vec<Case> {
    let bad_buffer = |name, uri: &'static str, problem| {
        let files = simpleskin_case(|j| j["buffers"][0]["uri"] = json!(uri));
        skin_case(name, files, Expect::Error(problem))
    };
    let bad_image = |name, uri: &'static str| {
        let files = simpleskin_case(|j| {
            j["images"] = json!([{ "uri": uri }]);
            j["textures"] = json!([{ "source": 0 }]);
        });
        skin_case(name, files, Expect::Success)
    };
    let careless = CARELESS.iter().map(|&(name, args, problem)| Case {
        name,
        files: riggedsimple(),
        args,
        outputs: vec![],
        expect: Expect::Error(problem),
    });
    let mut cases = vec![
        bad_buffer(
            "buffer-dotdot",
            "../secret.bin",
            "outside the document's folder",
        ),
        bad_buffer(
            "buffer-percent",
            "%2E%2E/secret.bin",
            "outside the document's folder",
        ),
        bad_buffer("buffer-absolute", "/etc/passwd", "absolute path"),
        bad_buffer(
            "buffer-dev-zero",
            "../../../../../../../../../../../../../../../../dev/zero",
            "outside",
        ),
        bad_buffer(
            "buffer-file-scheme",
            "file:///dev/urandom",
            "not a data: URI",
        ),
        skin_case(
            "buffer-link-outside",
            plus(
                simpleskin_case(|j| j["buffers"][0]["uri"] = json!("link.bin")),
                "link.bin",
                Source::Link("{secret}"),
            ),
            Expect::Error("outside the document's folder"),
        ),
        skin_case(
            "buffer-fifo",
            plus(
                simpleskin_case(|j| j["buffers"][0]["uri"] = json!("pipe.bin")),
                "pipe.bin",
                Source::Fifo,
            ),
            Expect::Error("not a regular file"),
        ),
        skin_case(
            "buffer-read-600-times",
            plus(
                simpleskin_case(|j| {
                    let big = json!({"uri": "big.bin", "byteLength": 16 << 20});
                    let buffers = j["buffers"].as_array_mut().unwrap();
                    buffers.extend(std::iter::repeat_n(big, 600));
                }),
                "big.bin",
                Source::Bytes(vec![7; 16 << 20]),
            ),
            Expect::Error("a document may load"),
        ),
        skin_case(
            "accessors-beyond-the-budget",
            simpleskin_case(|j| {
                let accessors = j["accessors"].as_array_mut().unwrap();
                let zeros = accessors.len();
                accessors.push(json!({"componentType": 5126, "count": 1 << 24, "type": "MAT4"}));
                j["skins"][0]["inverseBindMatrices"] = json!(zeros);
            }),
            Expect::Error("budget"),
        ),
        skin_case(
            "position-without-bounds",
            simpleskin_case(|j| {
                let position = j["accessors"][1].as_object_mut().unwrap();
                position.remove("min");
                position.remove("max");
            }),
            Expect::Success,
        ),
        skin_case(
            "projective-inverse-bind-matrix",
            simpleskin_case(|j| {
                use base64::Engine;
                let engine = base64::engine::general_purpose::STANDARD;
                // Buffer 2 holds the inverse bind matrices: joint 0's last row gets x = 0.5.
                let uri = j["buffers"][2]["uri"].as_str().unwrap().to_string();
                let (header, data) = uri.split_once(',').unwrap();
                let mut bytes = engine.decode(data).unwrap();
                bytes[12..16].copy_from_slice(&0.5f32.to_le_bytes());
                j["buffers"][2]["uri"] = json!(format!("{header},{}", engine.encode(bytes)));
            }),
            Expect::Success,
        ),
        skin_case(
            "joint-with-the-skinned-mesh",
            simpleskin_case(|j| j["nodes"][1]["mesh"] = json!(0)),
            Expect::Error("is a joint of the skin and also instantiates"),
        ),
        Case {
            name: "inspect-200k-node-chain",
            files: simpleskin_case(|j| {
                // Node 0 holds the skinned mesh; nodes 1..=N form one chain of joints.
                let count = 200_000;
                let mut nodes = vec![json!({"mesh": 0, "skin": 0})];
                nodes.extend((1..=count).map(|n| {
                    let mut node = json!({"translation": [0.0, 0.001, 0.0]});
                    if n < count {
                        node["children"] = json!([n + 1]);
                    }
                    node
                }));
                j["nodes"] = json!(nodes);
                j["scenes"] = json!([{"nodes": [0, 1]}]);
                j["skins"] = json!([{"joints": (1..=count).collect::<Vec<_>>()}]);
                j.as_object_mut().unwrap().remove("animations");
            }),
            args: "inspect {doc}/in.gltf",
            outputs: vec![],
            expect: Expect::Success,
        },
        bad_image("image-dotdot", "../secret.bin"),
        bad_image("image-absolute", "/etc/passwd"),
        bad_image(
            "image-dev-urandom",
            "../../../../../../../../../../../../../../../../dev/urandom",
        ),
        Case {
            name: "output-is-a-fifo",
            files: plus(riggedsimple(), "out.glb", Source::Fifo),
            args: "skin {doc}/in.glb -o {doc}/out.glb",
            outputs: vec![],
            expect: Expect::Error("not a regular file"),
        },
        Case {
            name: "output-is-a-link-to-a-file-outside",
            files: plus(riggedsimple(), "out.glb", Source::Link("{secret}")),
            args: "pose {doc}/in.glb --random 1 -o {doc}/out.glb",
            // The link is replaced by the output; the file it pointed to is untouched.
            outputs: vec!["doc/out.glb"],
            expect: Expect::Success,
        },
        Case {
            name: "output-is-the-skeleton",
            files: vec![
                (
                    "in.obj",
                    Source::Bytes(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".to_vec()),
                ),
                (
                    "in.tgf",
                    Source::Bytes(b"1 0 0 0\n2 1 0 0\n#\n1 2\n#\n".to_vec()),
                ),
            ],
            args: "skin {doc}/in.obj --skeleton {doc}/in.tgf -o {doc}/in.tgf",
            outputs: vec![],
            expect: Expect::Error("refusing to write over the input file"),
        },
        Case {
            name: "output-is-the-config",
            files: plus(riggedsimple(), "config.json", Source::Bytes(b"{}".to_vec())),
            args: "skin {doc}/in.glb --config {doc}/config.json -o {doc}/config.json",
            outputs: vec![],
            expect: Expect::Error("refusing to write over the input file"),
        },
        Case {
            name: "config-max-influences-huge",
            files: plus(
                riggedsimple(),
                "config.json",
                Source::Bytes(br#"{"max_influences": 1000000}"#.to_vec()),
            ),
            args: "skin {doc}/in.glb --config {doc}/config.json -o {case}/o.glb",
            outputs: vec!["o.glb"],
            expect: Expect::Error("max_influences 1000000 is outside 1..=32"),
        },
    ];
    cases.extend(careless);
    cases
}

/// Every file under `dir` (links not followed) with its bytes; links and FIFOs as empty.
fn snapshot(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut files = BTreeMap::new();
    let mut pending = vec![dir.to_path_buf()];
    while let Some(folder) = pending.pop() {
        for entry in std::fs::read_dir(&folder).unwrap() {
            let path = entry.unwrap().path();
            let kind = std::fs::symlink_metadata(&path).unwrap().file_type();
            if kind.is_dir() {
                pending.push(path);
            } else if kind.is_file() {
                files.insert(path.clone(), std::fs::read(&path).unwrap());
            } else {
                files.insert(path, Vec::new());
            }
        }
    }
    files
}

fn fill(text: &str, case: &Path) -> String {
    text.replace("{doc}", &case.join("doc").display().to_string())
        .replace("{case}", &case.display().to_string())
        .replace("{secret}", &case.join("secret.bin").display().to_string())
}

/// Runs `atlas-skin ARGS` under the memory and time limits.
fn run_limited(args: &[String]) -> Output {
    let script =
        format!("ulimit -v {MEMORY_LIMIT_KIB} && exec timeout -s KILL {TIME_LIMIT_SECONDS} \"$@\"");
    Command::new("sh")
        .arg("-c")
        .arg(script)
        .arg("sh")
        .arg(env!("CARGO_BIN_EXE_atlas-skin"))
        .args(args)
        .output()
        .expect("cannot run sh")
}

/// Runs one case in `root/NAME` and returns its glb outputs, to validate; a message per
/// failed check.
fn run_case(root: &Path, case: &Case, failures: &mut Vec<String>) -> Vec<PathBuf> {
    let dir = root.join(case.name);
    let doc = dir.join("doc");
    std::fs::create_dir_all(&doc).unwrap();
    std::fs::write(dir.join("secret.bin"), SECRET).unwrap();
    for (name, source) in &case.files {
        let path = doc.join(name);
        match source {
            Source::Bytes(bytes) => std::fs::write(&path, bytes).unwrap(),
            Source::Link(target) => std::os::unix::fs::symlink(fill(target, &dir), &path).unwrap(),
            Source::Fifo => {
                let made = Command::new("mkfifo").arg(&path).status().unwrap();
                assert!(made.success(), "mkfifo {}", path.display());
            }
        }
    }
    let before = snapshot(&dir);
    let args: Vec<String> = case.args.split(' ').map(|a| fill(a, &dir)).collect();
    let output = run_limited(&args);
    let stderr = String::from_utf8_lossy(&output.stderr);
    let mut fail = |message: String| failures.push(format!("{}: {message}", case.name));
    if stderr.contains("panicked") || output.status.code().is_none_or(|c| c > 2) {
        fail(format!(
            "exit {:?} (panic, abort, or time/memory limit): {stderr}",
            output.status
        ));
    }
    match case.expect {
        Expect::Error(fragment) => {
            if output.status.success() || !stderr.contains("error") || !stderr.contains(fragment) {
                fail(format!(
                    "expected an error with {fragment:?}, got {:?}: {stderr}",
                    output.status
                ));
            }
        }
        Expect::Success => {
            if !output.status.success() {
                fail(format!("failed: {stderr}"));
            }
        }
    }
    let outputs: Vec<PathBuf> = case.outputs.iter().map(|o| dir.join(o)).collect();
    let after = snapshot(&dir);
    for (path, bytes) in &before {
        if !outputs.contains(path) && after.get(path) != Some(bytes) {
            fail(format!("{} changed or vanished", path.display()));
        }
    }
    for (path, bytes) in &after {
        if !before.contains_key(path) && !outputs.contains(path) {
            fail(format!("{} appeared", path.display()));
        }
        if path != &dir.join("secret.bin") && bytes.windows(SECRET.len()).any(|w| w == SECRET) {
            fail(format!("{} holds the secret", path.display()));
        }
    }
    if output.status.success() {
        for out in &outputs {
            if !out.is_file() {
                fail(format!("no output {}", out.display()));
            }
        }
    }
    outputs
        .into_iter()
        .filter(|o| o.is_file() && o.extension().is_some_and(|e| e == "glb"))
        .collect()
}

#[test]
fn hostile_files_and_careless_commands_end_cleanly() {
    let root = out_dir("hostile");
    let mut failures = Vec::new();
    let mut written = Vec::new();
    for case in cases() {
        written.extend(run_case(&root, &case, &mut failures));
    }
    for report in node_check("validate.mjs", &written) {
        if report["errors"] != 0 {
            failures.push(format!("invalid output: {report}"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

//! `atlas-skin bench` and `atlas-skin pose` without INPUT: both run on the built-in demo
//! character skinned by the method.

use atlas_skin::fixtures::demo::{demo_character, DEFAULT_STEP};
use serde_json::Value;

mod support;

use support::{atlas_skin_ok, obj_positions, test_file};

/// Runs `atlas-skin ARGS...`, which must succeed, and returns its standard output.
fn atlas_skin(args: &[&str]) -> String {
    String::from_utf8(atlas_skin_ok(args).stdout).expect("UTF-8 output")
}

fn bench_json(threads: &str, weight_format: &str, vertex_order: &str) -> Value {
    let text = atlas_skin(&[
        "bench",
        "--json",
        "--threads",
        threads,
        "--vertices",
        "20000",
        "--frames",
        "3",
        "--weight-format",
        weight_format,
        "--vertex-order",
        vertex_order,
    ]);
    serde_json::from_str(&text).expect("one JSON object")
}

/// The JSON report has every figure the issue names, for the requested size, threads and
/// weight format (8-bit weights: 3 bytes fewer per explicit weight) and vertex order
/// (grouped by influence count: fewer influences blended per vertex).
/// (That a frame allocates nothing is the runtime's `tests/no_allocation.rs`.)
#[test]
fn bench_runs_on_the_demo_character() {
    let single = bench_json("1", "f32", "mesh");
    assert_eq!(single["threads"], 1, "{single}");
    assert_eq!(single["weight_format"], "f32", "{single}");
    assert_eq!(single["vertex_order"], "mesh", "{single}");
    let report = bench_json("2", "unorm8", "influences");
    assert_eq!(report["vertex_order"], "influences", "{report}");
    let blended = |r: &Value| {
        r["blended_influences"]
            .as_f64()
            .expect("blended influences")
    };
    assert!(blended(&report) < blended(&single), "{single} {report}");
    assert!(blended(&report) >= 1.0, "{report}");
    assert_eq!(report["vertices"], 20_000, "{report}");
    assert_eq!(report["threads"], 2, "{report}");
    assert_eq!(report["weight_format"], "unorm8", "{report}");
    let influences = report["influences"].as_u64().expect("influences");
    assert!((1..=4).contains(&influences), "{report}");
    let bytes = |r: &Value| r["bytes_per_vertex"].as_u64().expect("bytes per vertex");
    assert_eq!(bytes(&single) - bytes(&report), 3 * (influences - 1));
    for key in [
        "lbs_vertices_per_second",
        "dqs_vertices_per_second",
        "memcpy_bytes_per_second",
        "bandwidth_fraction",
        "dqs_bandwidth_fraction",
    ] {
        let value = report[key].as_f64().unwrap_or(f64::NAN);
        assert!(value.is_finite() && value > 0.0, "{key}: {report}");
    }
}

/// `pose` without INPUT deforms the demo character: the rest pose (an empty pose file) is
/// the demo mesh within 1e-5 of its bounding-box diagonal, a random pose moves it.
#[test]
fn pose_runs_on_the_demo_character() {
    let demo = demo_character(DEFAULT_STEP);
    let (min, max) = demo.positions.iter().fold(
        (glam::Vec3::splat(f32::MAX), glam::Vec3::splat(f32::MIN)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let diagonal = (max - min).length();
    let empty = test_file("bench_cli", "empty.json");
    std::fs::write(&empty, "{}").expect("pose file written");
    let rest = test_file("bench_cli", "rest.obj");
    let random = test_file("bench_cli", "random.obj");
    for (source, out) in [
        (["--pose", empty.to_str().expect("UTF-8 path")], &rest),
        (["--random", "5"], &random),
    ] {
        let mut args = vec!["pose"];
        args.extend(source);
        args.extend(["-o", out.to_str().expect("UTF-8 path")]);
        atlas_skin(&args);
    }
    let distance = |a: [f32; 3], b: glam::Vec3| (glam::Vec3::from_array(a) - b).length();
    let rest = obj_positions(&rest);
    assert_eq!(rest.len(), demo.positions.len());
    let worst = rest
        .iter()
        .zip(&demo.positions)
        .map(|(&a, &b)| distance(a, b))
        .fold(0.0f32, f32::max);
    assert!(worst <= 1e-5 * diagonal, "rest pose moved by {worst}");
    let random = obj_positions(&random);
    assert_eq!(random.len(), demo.positions.len());
    let moved = random
        .iter()
        .zip(&demo.positions)
        .map(|(&a, &b)| distance(a, b))
        .fold(0.0f32, f32::max);
    assert!(
        moved > 0.05 * diagonal,
        "a random pose moved by {moved} only"
    );
}

/// `--write-data` writes the side-by-side data file of ../shared/perf/README.md (header,
/// then 48 bytes per vertex and 64 per joint), `--batch` times samples of several frames,
/// `--instruction-set` picks the loops (the portable ones run on every CPU); a folder as
/// the data file and an unknown instruction set are refused with their names.
#[test]
fn bench_writes_side_by_side_data() {
    let data = test_file("bench_cli", "demo.bin");
    let text = atlas_skin(&[
        "bench",
        "--json",
        "--frames",
        "2",
        "--batch",
        "3",
        "--instruction-set",
        "portable",
        "--write-data",
        data.to_str().expect("UTF-8 path"),
    ]);
    let report: Value = serde_json::from_str(&text).expect("one JSON object");
    assert_eq!(report["batch"], 3, "{report}");
    assert_eq!(report["instruction_set"], "portable", "{report}");
    let bytes = std::fs::read(&data).expect("data file written");
    let int = |at: usize| i32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"));
    let (vertices, joints) = (int(0) as usize, int(4) as usize);
    assert_eq!(
        vertices,
        report["vertices"].as_u64().expect("vertices") as usize
    );
    assert!(joints > 10, "{joints} joints");
    assert_eq!(bytes.len(), 8 + 48 * vertices + 64 * joints);
    let weights = 8 + 32 * vertices;
    for v in 0..vertices {
        let row: f32 = (0..4)
            .map(|i| {
                let at = weights + 16 * v + 4 * i;
                f32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"))
            })
            .sum();
        assert!((row - 1.0).abs() < 1e-5, "vertex {v}: weights sum to {row}");
    }
    let folder = support::out_dir("bench_cli_folder");
    let failed = support::atlas_skin(&[
        "bench",
        "--frames",
        "1",
        "--write-data",
        folder.to_str().expect("UTF-8 path"),
    ]);
    assert!(!failed.status.success());
    let message = String::from_utf8_lossy(&failed.stderr);
    assert!(
        message.contains(folder.to_str().expect("UTF-8 path")),
        "{message}"
    );
    for (flag, value) in [
        ("--instruction-set", "sse9"),
        ("--weight-format", "f16"),
        ("--vertex-order", "sorted"),
    ] {
        let failed = support::atlas_skin(&["bench", "--frames", "1", flag, value]);
        assert!(!failed.status.success());
        let message = String::from_utf8_lossy(&failed.stderr);
        assert!(message.contains(value), "{flag}: {message}");
    }
}

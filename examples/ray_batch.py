"""Skins a folder of characters on Ray, one task per character, with the atlas_skin Python
package, and collects the reports into one table (CSV).

    python examples/ray_batch.py INPUT_DIR OUT_DIR [--address ADDRESS] [--num-cpus N]
                                 [--table TABLE.csv] [--reports] [--max-influences N]

Every .glb, .gltf, .vrm and .fbx file under INPUT_DIR (with its subfolders) is skinned to
OUT_DIR/<name>.glb (and OUT_DIR/<name>.json with --reports), as `atlas-skin skin` does:
each output is written to a temporary file and renamed, so a lost task leaves no half
file. The table (default OUT_DIR/table.csv) has one row per character: status, error,
seconds, the node that ran it, and the report's counts. The exit code is 1 when any
character failed.

On a laptop or one machine, without --address: `ray.init()` starts a local Ray with
--num-cpus workers (default: every core). On a cluster, run the same command on a node of
it with `--address auto` (or from outside with `--address ray://HEAD:10001`, Ray Client):
INPUT_DIR and OUT_DIR must then be paths that every node sees (NFS, a mounted bucket), and
atlas_skin must be installed on every node (`pip install` of this repository into the
nodes' Python environment, or a wheel given to Ray's runtime_env `pip`).
"""

import argparse
import csv
import socket
import sys
import time
from pathlib import Path

import ray

CHARACTER_SUFFIXES = {".glb", ".gltf", ".vrm", ".fbx"}

# Columns of the table: per character, then the report's counts.
COLUMNS = ["input", "output", "status", "error", "seconds", "node", "warnings"]
COUNTS = ["vertices", "joints", "regions", "fallback_weighted_vertices", "max_influences"]


def characters(folder):
    """The character files under `folder`, sorted; refuses two with one name, which
    would write one output."""
    files = sorted(p for p in Path(folder).rglob("*") if p.is_file() and p.suffix.lower() in CHARACTER_SUFFIXES)
    seen = {}
    for path in files:
        if path.stem in seen:
            raise SystemExit(f"error: {seen[path.stem]} and {path} would both be written to {path.stem}.glb")
        seen[path.stem] = path
    return files


@ray.remote(num_cpus=1)
def skin_one(input_path, out_dir, reports, options):
    """One task: skins one character and returns its row of the table."""
    import atlas_skin

    output = Path(out_dir) / (Path(input_path).stem + ".glb")
    report_path = output.with_suffix(".json") if reports else None
    row = {"input": input_path, "output": str(output), "node": socket.gethostname()}
    start = time.perf_counter()
    try:
        report = atlas_skin.skin_file(input_path, output, report=report_path, **options)
    except (ValueError, FileNotFoundError) as error:
        row.update(status="failed", error=str(error), output="")
    else:
        row.update(status="ok", error="", warnings=len(report["warnings"]))
        row.update({key: report["counts"][key] for key in COUNTS})
    row["seconds"] = round(time.perf_counter() - start, 4)
    return row


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("input_dir")
    parser.add_argument("out_dir")
    parser.add_argument("--address", help="a running Ray cluster: auto, or ray://HEAD:10001")
    parser.add_argument("--num-cpus", type=int, help="workers of the local Ray (default: every core)")
    parser.add_argument("--table", help="the CSV table (default OUT_DIR/table.csv)")
    parser.add_argument("--reports", action="store_true", help="also write OUT_DIR/<name>.json")
    parser.add_argument("--max-influences", type=int, help="influences per vertex (default 4)")
    args = parser.parse_args(argv)

    files = characters(args.input_dir)
    if not files:
        raise SystemExit(f"error: {args.input_dir} holds no character file")
    out_dir = Path(args.out_dir).resolve()
    out_dir.mkdir(parents=True, exist_ok=True)
    # One task per core: each task's Rust code then runs on one thread.
    runtime_env = {"env_vars": {"RAYON_NUM_THREADS": "1"}}
    if args.address:
        ray.init(address=args.address, runtime_env=runtime_env)
    else:
        ray.init(num_cpus=args.num_cpus, runtime_env=runtime_env, include_dashboard=False)

    options = {} if args.max_influences is None else {"max_influences": args.max_influences}
    start = time.perf_counter()
    pending = [skin_one.remote(str(f.resolve()), str(out_dir), args.reports, options) for f in files]
    rows = ray.get(pending)
    seconds = time.perf_counter() - start

    table = Path(args.table) if args.table else out_dir / "table.csv"
    with open(table, "w", newline="") as stream:
        writer = csv.DictWriter(stream, fieldnames=COLUMNS + COUNTS)
        writer.writeheader()
        writer.writerows(rows)
    failed = [row for row in rows if row["status"] != "ok"]
    for row in failed:
        print(f"error: {row['error']}", file=sys.stderr)
    print(
        f"{len(rows)} characters: {len(rows) - len(failed)} skinned, {len(failed)} failed, "
        f"in {seconds:.1f} s ({(len(rows) - len(failed)) / seconds:.2f} characters/s); table: {table}"
    )
    ray.shutdown()
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())

"""examples/ray_batch.py on a local Ray of 2 CPUs: three corpus characters and a broken
file; every output equals what `atlas-skin skin` writes, the table has a row per file and
the exit code says that one failed."""

import csv
import subprocess
import sys

from conftest import ROOT, data


def test_ray_example_skins_a_folder(cli, tmp_path):
    inputs = tmp_path / "in"
    (inputs / "sub").mkdir(parents=True)
    sources = {
        "Knight": data("bench/kaykit/Knight.glb"),
        "1168": data("bench/rignet-val/1168.glb"),
        "CesiumMan": data("models/cesiumman/CesiumMan.glb"),
    }
    for name, source in sources.items():
        folder = inputs / "sub" if name == "1168" else inputs
        (folder / source.name).write_bytes(source.read_bytes())
    (inputs / "broken.glb").write_bytes(b"junk")
    out = tmp_path / "out"

    run = subprocess.run(
        [sys.executable, str(ROOT / "examples" / "ray_batch.py"), str(inputs), str(out), "--num-cpus", "2", "--reports"],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert run.returncode == 1, run.stderr
    assert "4 characters: 3 skinned, 1 failed" in run.stdout, run.stdout + run.stderr

    with open(out / "table.csv", newline="") as stream:
        rows = {row["input"].rsplit("/", 1)[-1]: row for row in csv.DictReader(stream)}
    assert sorted(rows) == ["1168.glb", "CesiumMan.glb", "Knight.glb", "broken.glb"]
    assert rows["broken.glb"]["status"] == "failed"
    assert "broken.glb: not a binary glTF" in rows["broken.glb"]["error"]
    for name, source in sources.items():
        row = rows[source.name]
        assert row["status"] == "ok", row
        assert int(row["vertices"]) > 0 and int(row["joints"]) > 0
        cli("skin", source, "-o", tmp_path / f"cli-{name}.glb")
        assert (out / f"{name}.glb").read_bytes() == (tmp_path / f"cli-{name}.glb").read_bytes(), name
        assert (out / f"{name}.json").is_file()
    assert not list(out.glob("broken*"))

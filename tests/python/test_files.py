"""skin_file and batch: the CLI's jobs from Python, with the same outputs."""

import json

import pytest

import atlas_skin
from conftest import data


def test_skin_file_writes_what_the_cli_writes(cli, tmp_path):
    source = data("bench/kaykit/Knight.glb")
    report = atlas_skin.skin_file(source, tmp_path / "py.glb", report=tmp_path / "py.json", max_influences=3)
    cli("skin", source, "-o", tmp_path / "cli.glb", "--max-influences", "3")
    assert (tmp_path / "py.glb").read_bytes() == (tmp_path / "cli.glb").read_bytes()
    assert report == json.loads((tmp_path / "py.json").read_text())
    assert report["counts"]["max_influences"] <= 3
    assert report["input"] == str(source)


def test_batch_skins_every_file_and_records_the_failures(tmp_path):
    inputs = tmp_path / "in"
    inputs.mkdir()
    for relative in ["bench/kaykit/Knight.glb", "bench/kaykit/Mage.glb"]:
        (inputs / relative.split("/")[-1]).write_bytes(data(relative).read_bytes())
    (inputs / "broken.glb").write_bytes(b"not a glb at all")
    result = atlas_skin.batch([inputs], tmp_path / "out", jobs=2, report=True)
    summary = result["summary"]
    assert (summary["files"], summary["ok"], summary["failed"], summary["skipped"]) == (3, 2, 1, 0)
    by_name = {r["input"].split("/")[-1]: r for r in result["records"]}
    assert by_name["broken.glb"]["status"] == "failed"
    assert "broken.glb" in by_name["broken.glb"]["error"]
    for name in ["Knight", "Mage"]:
        assert by_name[f"{name}.glb"]["status"] == "ok"
        assert (tmp_path / "out" / f"{name}.glb").is_file()
        assert (tmp_path / "out" / f"{name}.json").is_file()
    log = (tmp_path / "out" / "atlas-skin-batch.jsonl").read_text().splitlines()
    assert len(log) == 3

    again = atlas_skin.batch(str(inputs / "*.glb"), tmp_path / "out", resume=True, report=True)
    statuses = sorted(r["status"] for r in again["records"])
    assert statuses == ["failed", "skipped", "skipped"]


def test_batch_that_cannot_start(tmp_path):
    with pytest.raises(ValueError, match="matches no file"):
        atlas_skin.batch([str(tmp_path / "*.glb")], tmp_path / "out")
    with pytest.raises(ValueError, match="jobs must be at least 1"):
        atlas_skin.batch([data("bench/kaykit/Knight.glb")], tmp_path / "out", jobs=0)

"""skin_file and batch: the CLI's jobs from Python, with the same outputs."""

import json
import signal
import subprocess
import sys
import time

import numpy as np
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
    with pytest.raises(ValueError, match=r"jobs 0 is outside 1..=256"):
        atlas_skin.batch([data("bench/kaykit/Knight.glb")], tmp_path / "out", jobs=0)


def test_progress_sees_every_record_and_an_exception_stops_the_batch(tmp_path):
    inputs = tmp_path / "in"
    inputs.mkdir()
    knight = data("bench/kaykit/Knight.glb").read_bytes()
    for i in range(8):
        (inputs / f"knight{i}.glb").write_bytes(knight)
    seen = []
    result = atlas_skin.batch(inputs, tmp_path / "all", jobs=2, progress=seen.append)
    assert sorted(r["input"] for r in seen) == sorted(r["input"] for r in result["records"])
    assert len(seen) == 8

    class Stop(Exception):
        pass

    def stop_at_once(record):
        raise Stop(record["input"])

    with pytest.raises(Stop):
        atlas_skin.batch(inputs, tmp_path / "stopped", jobs=1, progress=stop_at_once)
    log = [json.loads(line) for line in (tmp_path / "stopped" / "atlas-skin-batch.jsonl").read_text().splitlines()]
    assert len(log) == 8
    statuses = [r["status"] for r in log]
    assert statuses.count("cancelled") >= 1, statuses
    assert set(statuses) <= {"ok", "cancelled"}
    written = sorted(p.name for p in (tmp_path / "stopped").glob("*.glb"))
    assert written == sorted(r["output"].rsplit("/", 1)[-1] for r in log if r["status"] == "ok")


def interrupted(script, log, records, **popen):
    """Runs `script` in a child Python and sends it SIGINT once its batch `log` holds
    `records` records; returns its exit code and stderr."""
    child = subprocess.Popen([sys.executable, "-c", script], stderr=subprocess.PIPE, text=True, **popen)
    try:
        deadline = time.monotonic() + 120
        while not (log.exists() and log.read_text().count("\n") >= records):
            assert child.poll() is None and time.monotonic() < deadline, "the batch ended or did not start"
            time.sleep(0.005)
        child.send_signal(signal.SIGINT)
        _, stderr = child.communicate(timeout=120)
    finally:
        child.kill()
    return child.returncode, stderr


def test_ctrl_c_stops_a_batch(tmp_path):
    """SIGINT while the batch runs (the calling thread waiting for records in Rust):
    KeyboardInterrupt, every file logged, the rest cancelled.

    The batch cannot run more than ``jobs`` files ahead of the thread that checks for
    signals (the records wait in a channel of ``jobs`` places), so once the signal is
    sent at most 3 more files finish, however the threads are scheduled; the test only
    needs to send it before the 63 files left are done (seconds). The child installs
    Python's KeyboardInterrupt handler itself: a Python started with SIGINT ignored keeps
    it ignored (as the shell leaves it for a background job), and a CI runner that started
    the tests so made the batch run to its end and exit 0.
    """
    out = tmp_path / "out"
    log = out / "atlas-skin-batch.jsonl"
    script = (
        "import signal, atlas_skin\n"
        "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
        f"atlas_skin.batch({str(data('bench'))!r}, {str(out)!r}, jobs=1)\n"
    )
    returncode, stderr = interrupted(script, log, records=2)
    assert returncode != 0
    assert "KeyboardInterrupt" in stderr
    records = [json.loads(line) for line in log.read_text().splitlines()]
    assert len(records) == 65
    statuses = [r["status"] for r in records]
    assert set(statuses) == {"ok", "cancelled"}, statuses
    assert 2 <= statuses.count("ok") <= 5, statuses


def test_ctrl_c_stops_a_batch_its_progress_paused(tmp_path):
    """The same, deterministic whatever the scheduling: the child's ``progress`` pauses the
    batch at its second record (the workers wait for it, at most ``jobs`` records ahead)
    and says so; SIGINT then raises KeyboardInterrupt in ``progress``, which stops the
    batch: of the 65 files, at most 4 are skinned, the others cancelled."""
    out = tmp_path / "out"
    script = (
        "import signal, atlas_skin\n"
        "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
        "seen = []\n"
        "def pause(record):\n"
        "    seen.append(record)\n"
        "    if len(seen) == 2:\n"
        "        print('paused', flush=True)\n"
        "        signal.pause()\n"
        f"atlas_skin.batch({str(data('bench'))!r}, {str(out)!r}, jobs=1, progress=pause)\n"
    )
    child = subprocess.Popen(
        [sys.executable, "-c", script], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    try:
        assert child.stdout.readline() == "paused\n"
        child.send_signal(signal.SIGINT)
        _, stderr = child.communicate(timeout=120)
    finally:
        child.kill()
    assert child.returncode != 0 and "KeyboardInterrupt" in stderr, stderr
    records = [json.loads(line) for line in (out / "atlas-skin-batch.jsonl").read_text().splitlines()]
    assert len(records) == 65
    statuses = [r["status"] for r in records]
    assert set(statuses) == {"ok", "cancelled"}, statuses
    assert 2 <= statuses.count("ok") <= 4, statuses


def test_a_python_that_ignores_sigint_finishes_its_batch(tmp_path):
    """The other side of the test above: SIGINT ignored (inherited, as by a background job
    of a non-interactive shell), the batch is not interrupted and ends normally."""
    out = tmp_path / "out"
    log = out / "atlas-skin-batch.jsonl"
    inputs = [data(f"bench/kaykit/{name}.glb") for name in ("Knight", "Mage", "Barbarian", "Rogue_Hooded")]
    script = f"import atlas_skin; atlas_skin.batch({[str(p) for p in inputs]!r}, {str(out)!r}, jobs=1)"
    ignore = lambda: signal.signal(signal.SIGINT, signal.SIG_IGN)  # noqa: E731
    returncode, stderr = interrupted(script, log, records=1, preexec_fn=ignore)
    assert returncode == 0, stderr
    statuses = [json.loads(line)["status"] for line in log.read_text().splitlines()]
    assert statuses == ["ok"] * 4


def test_skin_file_with_a_gate_raises_quality_gate_error(tmp_path):
    source = data("bench/rignet-val/1168.glb")
    with pytest.raises(atlas_skin.QualityGateError) as caught:
        atlas_skin.skin_file(source, tmp_path / "out.glb", report=tmp_path / "out.json", fail_on="soft-joints")
    error = caught.value
    assert error.reasons and all(r.startswith("soft-joints: ") for r in error.reasons)
    assert error.report["quality"]["rejected"] and error.report["quality"]["fail_on"] == ["soft-joints"]
    assert error.output is None
    assert "the quality gate rejected" in str(error) and str(source) in str(error)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.rejected.json"]

    with pytest.raises(atlas_skin.QualityGateError) as caught:
        atlas_skin.skin_file(source, tmp_path / "out.glb", fail_on=["placement", "unweighted-joints"], keep_rejected=True)
    assert caught.value.output == str(tmp_path / "out.rejected.glb")
    assert all(r.startswith("unweighted-joints: ") for r in caught.value.reasons)
    kept = atlas_skin.load(caught.value.output)
    assert kept["weights"] is not None
    assert not (tmp_path / "out.glb").exists()

    report = atlas_skin.skin_file(source, tmp_path / "out.glb", fail_on=["placement", "mesh"])
    assert not report["quality"]["rejected"] and report["quality"]["reasons"] == []
    assert (tmp_path / "out.glb").is_file() and not (tmp_path / "out.rejected.glb").exists()
    with pytest.raises(ValueError, match="not a condition of the quality gate"):
        atlas_skin.skin_file(source, tmp_path / "out.glb", fail_on=["soft-joint"])
    with pytest.raises(TypeError, match="fail_on"):
        atlas_skin.skin_file(source, tmp_path / "out.glb", fail_on=3)


def test_a_batch_with_a_gate_records_rejected_files(tmp_path):
    inputs = [data("models/riggedsimple/RiggedSimple.glb"), data("bench/rignet-val/1168.glb")]
    result = atlas_skin.batch(inputs, tmp_path / "out", jobs=2, fail_on="soft-joints", keep_rejected=True)
    by_name = {r["input"].split("/")[-1]: r for r in result["records"]}
    assert by_name["RiggedSimple.glb"]["status"] == "ok" and by_name["RiggedSimple.glb"]["reasons"] == []
    rejected = by_name["1168.glb"]
    assert rejected["status"] == "rejected" and rejected["reasons"][0].startswith("soft-joints: ")
    assert rejected["kept"] == str(tmp_path / "out" / "1168.rejected.glb")
    assert result["summary"]["rejected"] == 1 and result["summary"]["ok"] == 1


def test_compute_weights_with_a_gate(demo):
    """The demo is clean; with a stored vertex no triangle uses, `fallback` rejects it."""
    arrays = (demo["positions"], demo["triangles"], demo["joint_positions"], demo["parents"])
    options = dict(names=demo["names"], inverse_bind=demo["inverse_bind"])
    _, _, report = atlas_skin.compute_weights(*arrays, fail_on=["warnings", "fallback"], **options)
    assert report["quality"] == {
        "fail_on": ["warnings", "fallback"],
        "reasons": [],
        "rejected": False,
        "soft_joints_without_weight": [],
        "unweighted_joints": [],
    }
    positions = np.vstack([demo["positions"], [[0.0, 1.0, 0.5]]])
    with pytest.raises(atlas_skin.QualityGateError) as caught:
        atlas_skin.compute_weights(positions, *arrays[1:], fail_on="fallback", **options)
    assert caught.value.reasons == ["fallback: 1 vertices weighted by a fallback"]
    assert caught.value.report["warning_topics"] == ["mesh"]

"""transfer and transfer_file: weight transfer on numpy arrays and the job of
`atlas-skin transfer` from Python."""

import numpy as np
import pytest

import atlas_skin
from conftest import data


def knight():
    c = atlas_skin.load(data("bench/kaykit/Knight.glb"))
    return c


def test_a_target_on_the_source_takes_the_source_weights():
    c = knight()
    target = c["positions"] * np.float32(1.001)
    indices, weights, info = atlas_skin.transfer(
        c["positions"], c["triangles"], c["indices"], c["weights"], target, c["triangles"],
        joint_count=len(c["names"]), max_influences=4,
    )
    assert indices.shape == (len(target), 4) and weights.shape == (len(target), 4)
    assert indices.dtype == np.uint32 and weights.dtype == np.float32
    np.testing.assert_allclose(weights.sum(axis=1), 1.0, atol=1e-5)
    assert info["counts"]["stored_vertices"] == len(target)
    assert info["counts"]["matched"] > 0.9 * info["counts"]["welded_vertices"]
    assert set(info["vertex_sources"]) <= {"matched", "inpainted", "nearest"}
    # The heaviest joint agrees with the file's own almost everywhere.
    own = c["indices"][np.arange(len(target)), np.argmax(c["weights"], axis=1)]
    assert np.mean(indices[:, 0] == own) > 0.95


def test_bad_arrays_and_far_targets_raise_value_error():
    c = knight()
    far = c["positions"] + np.float32(50.0)
    with pytest.raises(ValueError, match="rest space"):
        atlas_skin.transfer(c["positions"], c["triangles"], c["indices"], c["weights"], far, c["triangles"])
    with pytest.raises(ValueError, match="matching distance must be positive"):
        atlas_skin.transfer(
            c["positions"], c["triangles"], c["indices"], c["weights"], c["positions"], c["triangles"],
            distance=0.0,
        )
    with pytest.raises(ValueError, match="source_vertices"):
        atlas_skin.transfer(c["positions"][:, :2], c["triangles"], c["indices"], c["weights"], far, c["triangles"])


def test_transfer_file_writes_what_the_cli_writes(cli, tmp_path):
    source = data("bench/kaykit/Knight.glb")
    report = atlas_skin.transfer_file(source, [], tmp_path / "py.glb", meshes=["Knight_Helmet"], max_influences=3)
    cli("transfer", source, "--meshes", "Knight_Helmet", "-o", tmp_path / "cli.glb", "--max-influences", "3")
    assert (tmp_path / "py.glb").read_bytes() == (tmp_path / "cli.glb").read_bytes()
    assert report["targets"][0]["name"] == "Knight_Helmet"
    assert report["max_influences"] == 3
    with pytest.raises(FileNotFoundError):
        atlas_skin.transfer_file(tmp_path / "missing.glb", [source], tmp_path / "x.glb")
    with pytest.raises(ValueError, match="no mesh named"):
        atlas_skin.transfer_file(source, [], tmp_path / "x.glb", meshes=["nothing"])
    assert not (tmp_path / "x.glb").exists()

"""binding="rigid" in compute_weights, skin_file and batch: one joint of weight 1 per
vertex on a character its artist bound rigidly, the weights `atlas-skin skin --binding
rigid` writes."""

import numpy as np
import pytest

import atlas_skin
from conftest import data
from test_weights import assert_same_as_cli, weights_of

RIGID = "bench/rignet-val/1168.glb"


def assert_one_joint_each(indices, weights):
    """Every row has one weight 1 and zeros in its other slots."""
    positive = weights > 0
    assert (positive.sum(axis=1) == 1).all()
    assert (weights[positive] == 1.0).all()
    return indices[positive]


def test_compute_weights_binds_rigidly_as_the_cli(cli, tmp_path):
    source = data(RIGID)
    character = atlas_skin.load(source)
    cli("skin", source, "-o", tmp_path / "rigid.glb", "--binding", "rigid")
    indices, weights, report = assert_same_as_cli(character, tmp_path / "rigid.glb", binding="rigid")
    assert report["binding"] == "rigid"
    assert report["counts"]["max_influences"] == 1
    joints = assert_one_joint_each(indices, weights)
    # The smooth weights of the same character blend, and their heaviest joint is the rigid
    # one wherever it holds more than half of the row.
    smooth_indices, smooth_weights, smooth_report = weights_of(character)
    assert smooth_report["binding"] == "smooth"
    assert (np.count_nonzero(smooth_weights, axis=1) > 1).sum() > 100
    majority = smooth_weights.max(axis=1) > 0.5
    heaviest = smooth_indices[np.arange(len(smooth_indices)), smooth_weights.argmax(axis=1)]
    np.testing.assert_array_equal(joints[majority], heaviest[majority])


def test_skin_file_and_batch_bind_rigidly(cli, tmp_path):
    source = data(RIGID)
    report = atlas_skin.skin_file(source, tmp_path / "py.glb", binding="rigid")
    cli("skin", source, "-o", tmp_path / "cli.glb", "--binding", "rigid")
    assert (tmp_path / "py.glb").read_bytes() == (tmp_path / "cli.glb").read_bytes()
    assert report["binding"] == "rigid"
    result = atlas_skin.batch([source], tmp_path / "out", binding="rigid")
    assert result["summary"]["ok"] == 1
    assert (tmp_path / "out" / "1168.glb").read_bytes() == (tmp_path / "cli.glb").read_bytes()
    written = atlas_skin.load(tmp_path / "cli.glb")
    assert_one_joint_each(written["indices"], written["weights"])


def test_a_wrong_binding_is_refused(demo):
    with pytest.raises(ValueError, match='binding must be "smooth" or "rigid", got "stiff"'):
        weights_of(demo, binding="stiff")
    with pytest.raises(TypeError, match="binding"):
        weights_of(demo, binding=1)

"""compute_weights on numpy arrays gives the weights `atlas-skin skin` writes (read back
from its glb by `load`), on the demo character and on real characters."""

import numpy as np
import pytest

import atlas_skin
from conftest import data


def dense(indices, weights, joint_count):
    """(V, J) weights from (V, K) indices and weights."""
    out = np.zeros((indices.shape[0], joint_count))
    np.add.at(out, (np.arange(indices.shape[0])[:, None], indices), weights)
    return out


def weights_of(character, **options):
    return atlas_skin.compute_weights(
        character["positions"],
        character["triangles"],
        character["joint_positions"],
        character["parents"],
        tails=character["tails"],
        inverse_bind=character["inverse_bind"],
        names=character["names"],
        end_joints=character["end_joints"],
        **options,
    )


def assert_same_as_cli(character, skinned_glb, **options):
    indices, weights, report = weights_of(character, **options)
    written = atlas_skin.load(skinned_glb)
    assert written["names"] == character["names"]
    joints = len(character["names"])
    ours = dense(indices, weights, joints)
    theirs = dense(written["indices"], written["weights"], joints)
    assert ours.shape == theirs.shape
    assert np.abs(ours - theirs).max() <= 1e-6
    return indices, weights, report


def test_demo_weights_equal_the_cli(cli, demo, tmp_path):
    cli("skin", "-o", tmp_path / "demo.glb")
    indices, weights, report = assert_same_as_cli(demo, tmp_path / "demo.glb")
    assert indices.dtype == np.uint32 and weights.dtype == np.float32
    assert indices.shape == weights.shape == (16000, 4)
    np.testing.assert_allclose(weights.sum(axis=1), 1.0, atol=1e-6)
    assert report["counts"]["vertices"] == 16000
    assert report["input"] == "the given arrays"


@pytest.mark.parametrize("relative", ["models/cesiumman/CesiumMan.glb", "bench/kaykit/Knight.glb"])
def test_corpus_weights_equal_the_cli(cli, tmp_path, relative):
    source = data(relative)
    cli("skin", source, "-o", tmp_path / "out.glb")
    assert_same_as_cli(atlas_skin.load(source), tmp_path / "out.glb")


def test_options_reach_the_method(cli, demo, tmp_path):
    """max_influences, overlap, blend and forbid as the CLI's flags."""
    args = ["--max-influences", "2", "--overlap", "0.3", "--blend", "paper", "--forbid", demo["names"][3]]
    cli("skin", "-o", tmp_path / "demo.glb", *args)
    indices, weights, report = assert_same_as_cli(
        demo, tmp_path / "demo.glb", max_influences=2, overlap=0.3, blend="paper", forbid=[demo["names"][3]]
    )
    assert indices.shape == (16000, 2)
    default_indices, default_weights, _ = weights_of(demo, max_influences=2)
    assert not np.array_equal(dense(indices, weights, 35), dense(default_indices, default_weights, 35))


def test_float64_and_int64_inputs_give_the_same_weights(demo):
    a = atlas_skin.compute_weights(demo["positions"], demo["triangles"], demo["joint_positions"], demo["parents"])
    b = atlas_skin.compute_weights(
        demo["positions"].astype(np.float64),
        demo["triangles"].astype(np.int64),
        demo["joint_positions"].astype(np.float64),
        demo["parents"].astype(np.int32),
    )
    np.testing.assert_array_equal(a[0], b[0])
    np.testing.assert_array_equal(a[1], b[1])

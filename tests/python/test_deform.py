"""deform_lbs / deform_dqs against numpy: linear blend as Σ w·M·p, dual quaternions equal
to linear blend where a vertex has one influence, and bad input refused."""

import numpy as np
import pytest

import atlas_skin


def rotation_z(angle):
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])


def palette(joints, seed):
    rng = np.random.default_rng(seed)
    matrices = np.stack([rotation_z(a) for a in rng.uniform(-1, 1, joints)])
    matrices[:, :3, 3] = rng.uniform(-0.5, 0.5, (joints, 3))
    return matrices


def test_linear_blend_is_the_weighted_sum_of_matrices(demo):
    indices, weights, _ = atlas_skin.compute_weights(
        demo["positions"], demo["triangles"], demo["joint_positions"], demo["parents"]
    )
    matrices = palette(35, seed=1)
    posed = atlas_skin.deform_lbs(demo["positions"], indices, weights, matrices)
    homogeneous = np.hstack([demo["positions"], np.ones((16000, 1), np.float32)]).astype(np.float64)
    blended = np.einsum("vk,vkij->vij", weights, matrices[indices])
    expected = np.einsum("vij,vj->vi", blended, homogeneous)[:, :3]
    assert posed.dtype == np.float32 and posed.shape == (16000, 3)
    np.testing.assert_allclose(posed, expected, atol=1e-5)


def test_dual_quaternions_equal_linear_blend_for_single_influences():
    points = np.random.default_rng(2).uniform(-1, 1, (50, 3))
    indices = np.arange(50).reshape(50, 1) % 3
    weights = np.ones((50, 1))
    matrices = palette(3, seed=3)
    lbs = atlas_skin.deform_lbs(points, indices, weights, matrices)
    dqs = atlas_skin.deform_dqs(points, indices, weights, matrices)
    np.testing.assert_allclose(dqs, lbs, atol=1e-5)
    identity = np.repeat(np.eye(4)[None], 3, axis=0)
    np.testing.assert_allclose(atlas_skin.deform_dqs(points, indices, weights, identity), points, atol=1e-6)


def test_bad_posing_input():
    points = np.zeros((4, 3))
    indices = np.zeros((4, 2), np.int64)
    weights = np.full((4, 2), 0.5)
    identity = np.repeat(np.eye(4)[None], 2, axis=0)
    with pytest.raises(ValueError, match=r"palette must have shape \(J, 4, 4\), got \(2, 3, 4\)"):
        atlas_skin.deform_lbs(points, indices, weights, identity[:, :3])
    bad = indices.copy()
    bad[1, 1] = 2
    with pytest.raises(ValueError, match=r"indices\[1, 1\] is 2, but the palette has 2 joints"):
        atlas_skin.deform_dqs(points, bad, weights, identity)
    nan = weights.copy()
    nan[3, 0] = np.nan
    with pytest.raises(ValueError, match=r"weights\[3, 0\] is not finite"):
        atlas_skin.deform_lbs(points, indices, nan, identity)
    with pytest.raises(ValueError, match=r"weights must have shape \(4, 2\), got \(4, 3\)"):
        atlas_skin.deform_lbs(points, indices, np.ones((4, 3)), identity)

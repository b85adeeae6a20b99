"""scripts/rigidity-cues on shapes with known answers: dihedral angles of a cube, vertices
of one box inside another, the neck, the groove and the artist's hardness at the joint of a
tube, the AUC, and one rigidly bound bench character."""

import importlib.machinery
import importlib.util

import numpy as np
import pytest

from conftest import ROOT, data

loader = importlib.machinery.SourceFileLoader("rigidity_cues", str(ROOT / "scripts" / "rigidity-cues"))
spec = importlib.util.spec_from_loader("rigidity_cues", loader)
cues = importlib.util.module_from_spec(spec)
loader.exec_module(cues)


def box(center, size):
    """A closed box of 12 outward-wound triangles."""
    corners = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], float)
    positions = center + (corners - 0.5) * size
    faces = np.array([
        [0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
        [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    return positions, faces


def tube(radius_at, rings=21, sides=16):
    """A closed tube along y from 0 to 2 (rings every 0.1), capped at both ends."""
    positions, faces = [], []
    for k in range(rings):
        y = 2.0 * k / (rings - 1)
        r = radius_at(y)
        positions += [[r * np.cos(2 * np.pi * s / sides), y, r * np.sin(2 * np.pi * s / sides)] for s in range(sides)]
    for k in range(rings - 1):
        for s in range(sides):
            a, b = k * sides + s, k * sides + (s + 1) % sides
            faces += [[a, a + sides, b], [b, a + sides, b + sides]]
    bottom, top = len(positions), len(positions) + 1
    positions += [[0, 0, 0], [0, 2, 0]]
    last = (rings - 1) * sides
    for s in range(sides):
        faces += [[bottom, s, (s + 1) % sides], [top, last + (s + 1) % sides, last + s]]
    return np.array(positions, float), np.array(faces)


def arm(radius_at, blend_width):
    """A tube with joints at y = 0, 1, 2 (a chain), bound to the elbow above y = 1: rigidly
    when blend_width is 0, else blended linearly over y in 1 ± blend_width."""
    positions, faces = tube(radius_at)
    y = positions[:, 1]
    elbow = np.clip((y - 1 + blend_width) / (2 * blend_width), 0, 1) if blend_width else (y >= 1).astype(float)
    weights = np.stack([1 - elbow, elbow, np.zeros_like(y)], 1)
    return dict(positions=positions, faces=faces, weights=weights, diagonal=np.linalg.norm(positions.max(0) - positions.min(0)),
                parents=np.array([-1, 0, 1]), joints=np.array([[0, 0, 0], [0, 1, 0], [0, 2, 0]], float),
                names=["shoulder", "elbow", "tip"])


def joint_row(ch):
    edges, dihedral, _ = cues.manifold_edges(ch["positions"], ch["faces"])
    rows = cues.joint_cues(ch, edges, dihedral)
    assert [r["joint"] for r in rows] == ["elbow"]
    return rows[0]


def test_dihedral_angles_of_a_cube():
    positions, faces = box(np.zeros(3), 1.0)
    edges, dihedral, _ = cues.manifold_edges(positions, faces)
    assert len(edges) == 18
    assert np.sum(np.isclose(dihedral, 90)) == 12 and np.sum(np.isclose(dihedral, 0, atol=1e-6)) == 6


def test_only_the_vertex_inside_the_other_box_interpenetrates():
    a, fa = box(np.zeros(3), 1.0)
    b, fb = box(np.full(3, 0.9), 1.0)
    positions, faces = np.vstack([a, b]), np.vstack([fa, fb + 8])
    _, _, normals = cues.manifold_edges(positions, faces)
    inside = cues.interpenetrating(positions, faces, normals, 1.0)
    assert np.flatnonzero(inside).tolist() == [7, 8]
    alone = cues.interpenetrating(a, fa, cues.manifold_edges(a, fa)[2], 1.0)
    assert not alone.any()


def test_neck_groove_and_hardness_at_the_joint_of_a_tube():
    straight = joint_row(arm(lambda y: 0.2, 0.0))
    assert straight["neck"] == pytest.approx(1.0, abs=0.05)
    assert straight["crease_ring"] < 1.1
    assert straight["sharp_near"] == 0.0 and straight["blended"] == 0.0
    narrow = joint_row(arm(lambda y: 0.1 if abs(y - 1) < 0.15 else 0.2, 0.0))
    assert narrow["neck"] < 0.7
    grooved = joint_row(arm(lambda y: 0.1 if abs(y - 1) < 0.05 else 0.2, 0.3))
    assert grooved["sharp_near"] > 0.2 and grooved["crease_ring"] > 2.0
    assert grooved["blended"] > 0.2


def test_auc_counts_pairs_and_halves_ties():
    assert cues.auc([3, 4], [1, 2]) == 1.0
    assert cues.auc([1, 2], [3, 4]) == 0.0
    assert cues.auc([1, 2], [1, 2]) == 0.5
    assert cues.auc([1, np.nan], [0]) == 1.0


def test_a_rigidly_bound_bench_character():
    result = cues.cues(str(data("bench/rignet-val/6802.glb")))
    assert result["artist_single"] == 1.0
    assert all(r["blended"] == 0.0 for r in result["joints"])
    assert 0.0 <= result["interpenetrating"] < 1.0


def test_marked_joints_by_threshold():
    joints = [dict(joint="a", neck=0.8, crease_ring=2.5), dict(joint="b", neck=1.2, crease_ring=1.0),
              dict(joint="c", neck=np.nan, crease_ring=np.nan)]
    assert cues.marked_joints(joints, "neck", 0.9) == ["a"]
    assert cues.marked_joints(joints, "crease_ring", 1.0) == ["a", "b"]


def test_a_narrow_overlap_at_every_joint_binds_a_rigid_character_rigidly(cli, tmp_path):
    path = str(data("bench/rignet-val/6802.glb"))
    joints = [r["joint"] for r in cues.cues(path)["joints"]]
    _, _, default = cues.skin_with_narrow_joints(path, [], 0.05, str(tmp_path))
    mean, worst, narrow = cues.skin_with_narrow_joints(path, joints, 0.02, str(tmp_path))
    assert 0 < mean < worst
    assert default < 0.9 and narrow > default + 0.05

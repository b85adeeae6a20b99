"""Bad input raises ValueError (FileNotFoundError for a missing file) with a message naming
the argument or the file and the problem, the CLI's message where the CLI has one."""

import numpy as np
import pytest

import atlas_skin
from conftest import data


def weights(demo, **changes):
    arrays = dict(
        vertices=demo["positions"],
        triangles=demo["triangles"],
        joint_positions=demo["joint_positions"],
        parents=demo["parents"],
    )
    options = {k: changes.pop(k) for k in list(changes) if k not in arrays}
    arrays.update(changes)
    return atlas_skin.compute_weights(*arrays.values(), **options)


@pytest.mark.parametrize(
    "changes, message",
    [
        ({"vertices": np.zeros((10, 2))}, r"vertices must have shape \(V, 3\), got \(10, 2\)"),
        ({"vertices": np.zeros(30)}, r"vertices must have shape \(V, 3\), got \(30\)"),
        ({"triangles": np.zeros((4, 4), np.int64)}, r"triangles must have shape \(F, 3\), got \(4, 4\)"),
        ({"triangles": np.zeros((4, 3), np.float64)}, "triangles must hold integers, got float64"),
        ({"vertices": np.zeros((3, 3), np.int32)}, r"vertices must hold floats \(float32 or float64\), got int32"),
        ({"parents": np.zeros(3, np.int64)}, r"parents must have shape \(35\), got \(3\)"),
        ({"joint_positions": np.zeros((35, 4))}, r"joint_positions must have shape \(J, 3\)"),
    ],
)
def test_wrong_shapes_and_types(demo, changes, message):
    with pytest.raises(ValueError, match=message):
        weights(demo, **changes)


def test_values_that_are_not_finite(demo):
    vertices = demo["positions"].copy()
    vertices[7, 1] = np.nan
    with pytest.raises(ValueError, match=r"vertices\[7\] is not finite"):
        weights(demo, vertices=vertices)
    joints = demo["joint_positions"].copy()
    joints[2] = np.inf
    with pytest.raises(ValueError, match=r"joint_positions\[2\] is not finite"):
        weights(demo, joint_positions=joints)
    tails = np.full((35, 3), np.nan, np.float32)
    tails[4, 0] = 1.0
    with pytest.raises(ValueError, match=r"tails\[4\] is not finite"):
        weights(demo, tails=tails)


def test_bind_frames_that_disagree_with_the_joints(demo):
    frames = demo["inverse_bind"].copy()
    with pytest.raises(ValueError, match=r"inverse_bind must have shape \(35, 4, 4\), got \(3, 4, 4\)"):
        weights(demo, inverse_bind=frames[:3])
    frames[5, 0, 3] += 1.0
    with pytest.raises(ValueError, match=r"inverse_bind\[5\] places joint .* not at joint_positions\[5\]"):
        weights(demo, inverse_bind=frames)
    frames[5, 0, 3] = np.nan
    with pytest.raises(ValueError, match=r"inverse_bind\[5\] is not finite"):
        weights(demo, inverse_bind=frames)


def test_a_skeleton_without_joints(demo):
    with pytest.raises(ValueError, match="joint_positions is empty: a skeleton needs at least one joint"):
        weights(demo, joint_positions=np.zeros((0, 3)), parents=np.zeros(0, np.int64))


def test_indices_out_of_range(demo):
    triangles = demo["triangles"].astype(np.int64)
    triangles[5, 2] = 16000
    with pytest.raises(ValueError, match=r"triangles\[5\] uses vertex 16000, but there are 16000 vertices"):
        weights(demo, triangles=triangles)
    triangles[5, 2] = -1
    with pytest.raises(ValueError, match=r"triangles\[5\] uses vertex -1"):
        weights(demo, triangles=triangles)
    parents = demo["parents"].copy()
    parents[3] = 35
    with pytest.raises(ValueError, match=r"parents\[3\] is 35: neither -1 \(a root\) nor a joint index below 35"):
        weights(demo, parents=parents)
    parents[3] = 3
    with pytest.raises(ValueError, match="invalid skeleton: .*cycle"):
        weights(demo, parents=parents)
    with pytest.raises(ValueError, match="end_joints holds 99"):
        weights(demo, end_joints=[99])


def test_bad_options(demo):
    with pytest.raises(ValueError, match=r"max_influences 0 is outside 1..=32"):
        weights(demo, max_influences=0)
    with pytest.raises(ValueError, match=r"max_influences -2 is outside 1..=32"):
        weights(demo, max_influences=-2)
    with pytest.raises(ValueError, match='blend must be "pou" or "paper", got "linear"'):
        weights(demo, blend="linear")
    with pytest.raises(TypeError, match='unexpected keyword argument "overlapp"'):
        weights(demo, overlapp=0.3)
    with pytest.raises(ValueError, match="names must be unique"):
        weights(demo, names=["a"] * 35)
    with pytest.raises(FileNotFoundError, match="cannot read /nonexistent/settings.json"):
        weights(demo, config="/nonexistent/settings.json")


def test_the_method_refusing_input_gives_the_cli_message(demo, cli):
    """A skeleton far outside the mesh: the message is the CLI's, with the input named."""
    far = demo["joint_positions"] + np.float32(100.0)
    with pytest.raises(ValueError) as caught:
        weights(demo, joint_positions=far)
    message = str(caught.value)
    assert message.startswith("cannot skin the given arrays: ")
    assert "\n" not in message


def test_missing_and_broken_files(tmp_path, cli):
    with pytest.raises(FileNotFoundError, match=r"/nonexistent/x.glb: cannot read"):
        atlas_skin.load("/nonexistent/x.glb")
    with pytest.raises(FileNotFoundError, match=r"/nonexistent/x.glb: cannot read"):
        atlas_skin.skin_file("/nonexistent/x.glb", tmp_path / "out.glb")
    broken = tmp_path / "broken.glb"
    broken.write_bytes(b"glTF\x02\x00\x00\x00garbage")
    cli_error = cli("skin", broken, "-o", tmp_path / "cli.glb", check=False).stderr.strip()
    assert cli_error.startswith("error: ")
    with pytest.raises(ValueError) as caught:
        atlas_skin.skin_file(broken, tmp_path / "out.glb")
    assert str(caught.value) == cli_error.removeprefix("error: ")
    assert not (tmp_path / "out.glb").exists()
    with pytest.raises(ValueError, match="refusing to write over the input file"):
        atlas_skin.skin_file(data("bench/kaykit/Knight.glb"), data("bench/kaykit/Knight.glb"))

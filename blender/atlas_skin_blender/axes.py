"""The armature's space to the space atlas-skin works in.

The weights are computed in the armature's space (its rest pose; every mesh carried
into it by its object transform), the space in which a glTF or FBX file states the
skeleton and the skinned mesh, so the method sees a character imported into Blender as the
command line sees the file. atlas-skin reads characters as glTF stores them (metres, +Y
up, +Z front); Blender is +Z up, -Y front, and its glTF importer maps a glTF point
(x, y, z) to (x, -z, y). The add-on hands atlas-skin the inverse, (x, y, z) -> (x, z, -y):
a permutation with one sign change, exact in floating point.
"""
import numpy as np

# Rows: glTF x, y, z in Blender's axes.
BLENDER_TO_GLTF = np.array(((1.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0.0, -1.0, 0.0)))


def to_gltf_axes(points, matrix=None):
    """(N, 3) points -> (N, 3) float64 in glTF's axes: BLENDER_TO_GLTF · (M · [p, 1]).

    matrix: the 4x4 transform M (array-like, e.g. a mathutils.Matrix) from the points'
    space to the armature's; None for points already there.
    """
    points = np.asarray(points, dtype=np.float64)
    if matrix is not None:
        m = np.asarray(matrix, dtype=np.float64)
        points = points @ m[:3, :3].T + m[:3, 3]
    return points @ BLENDER_TO_GLTF.T


def frames_to_gltf_axes(matrices):
    """(N, 4, 4) bone frames (local to armature, e.g. Bone.matrix_local) -> (N, 4, 4)
    float64 local to armature in glTF's axes: the bones' own axes kept (a Blender bone's +Y
    still runs from its head to its tail), their images turned into glTF's axes."""
    frames = np.asarray(matrices, dtype=np.float64).reshape(-1, 4, 4)
    to_gltf = np.eye(4)
    to_gltf[:3, :3] = BLENDER_TO_GLTF
    return to_gltf @ frames

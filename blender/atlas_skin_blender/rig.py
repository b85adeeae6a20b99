"""The deforming bones of an armature as atlas-skin's skeleton: joint positions, parents and
tails at the rest pose, in the armature's space with glTF's axes (see `axes.py`)."""
from dataclasses import dataclass

import numpy as np

from .axes import frames_to_gltf_axes, to_gltf_axes


class RigError(Exception):
    """An armature atlas-skin cannot weight (the message names the armature)."""


@dataclass
class Rig:
    """Joints of atlas-skin, one per deforming bone.

    names: J bone names; heads, tails: (J, 3) float64 positions of each bone's head and
    tail at rest (the armature's space, glTF's axes); parents: (J,) int64, the index of
    the nearest deforming ancestor or -1 for a root. Parents come before their children.
    inverse_bind: (J, 4, 4) float64, the inverse of each bone's rest frame in the same
    space (its +Y along the bone, as Blender's bones and glTF files made by Blender have
    it): a leaf bone's direction for the method.
    """

    names: list
    heads: np.ndarray
    tails: np.ndarray
    parents: np.ndarray
    inverse_bind: np.ndarray


def deforming_rig(armature):
    """The deforming bones of `armature` (Bone.use_deform), as Blender's own automatic
    weights take them: a bone that does not deform gets no group and its deforming children
    hang from its nearest deforming ancestor."""
    bones = [b for b in armature.data.bones if b.use_deform]
    if not bones:
        raise RigError(f"armature '{armature.name}' has no deforming bone")
    # Armature.bones lists the bones depth first: a parent before its children.
    index = {b.name: i for i, b in enumerate(bones)}
    parents = np.full(len(bones), -1, dtype=np.int64)
    for i, bone in enumerate(bones):
        ancestor = bone.parent
        while ancestor is not None and ancestor.name not in index:
            ancestor = ancestor.parent
        if ancestor is not None:
            parents[i] = index[ancestor.name]
    return Rig(
        names=[b.name for b in bones],
        heads=to_gltf_axes([b.head_local for b in bones]),
        tails=to_gltf_axes([b.tail_local for b in bones]),
        parents=parents,
        inverse_bind=np.linalg.inv(frames_to_gltf_axes([b.matrix_local for b in bones])),
    )

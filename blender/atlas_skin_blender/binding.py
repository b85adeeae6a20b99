"""Writing the weights into Blender: one vertex group per deforming bone, the Armature
modifier and the parent, as Blender's "With Automatic Weights" leaves a mesh."""
import numpy as np


def write_groups(obj, bone_names, indices, weights):
    """Replaces the groups of `bone_names` on mesh object `obj` by the weights.

    indices: (N, K) integer joint indices into bone_names and weights: (N, K) float, one
    row per vertex of obj (zero weights are left out). Every bone gets a group, empty or
    not (as Blender's automatic weights make them); a group of that name is emptied first,
    so running twice gives the same groups; groups of other names are kept as they are.
    """
    everything = list(range(len(obj.data.vertices)))
    groups = []
    for name in bone_names:
        group = obj.vertex_groups.get(name)
        if group is None:
            group = obj.vertex_groups.new(name=name)
        else:
            group.remove(everything)
        groups.append(group)
    rows = np.repeat(np.arange(indices.shape[0]), indices.shape[1])
    joints, values = indices.reshape(-1), np.asarray(weights, dtype=np.float64).reshape(-1)
    kept = values > 0.0
    rows, joints, values = rows[kept], joints[kept], values[kept]
    # One call per (bone, weight): whole regions share the weight 1.
    order = np.lexsort((values, joints))
    rows, joints, values = rows[order], joints[order], values[order]
    starts = np.flatnonzero(
        np.concatenate(([True], (joints[1:] != joints[:-1]) | (values[1:] != values[:-1])))
    )
    for start, end in zip(starts, np.append(starts[1:], len(rows))):
        groups[joints[start]].add(rows[start:end].tolist(), float(values[start]), "REPLACE")


def bind_to_armature(obj, armature):
    """Makes `armature` deform `obj` through its vertex groups: an Armature modifier for it
    (added first in the stack when there is none, so it deforms the mesh before
    generating modifiers such as Subdivision) and `armature` as the object's parent, the
    object staying where it is in the world: as Blender's Ctrl+P, an earlier parent's
    transform is applied to the object's own, and the parent inverse is the armature's
    inverse world matrix. To be called at the armature's rest pose."""
    modifier = next(
        (m for m in obj.modifiers if m.type == "ARMATURE" and m.object == armature), None
    )
    if modifier is None:
        modifier = obj.modifiers.new(name=armature.name, type="ARMATURE")
        modifier.object = armature
        obj.modifiers.move(len(obj.modifiers) - 1, 0)
    modifier.use_vertex_groups = True
    modifier.use_bone_envelopes = False
    if obj.parent == armature and obj.parent_type == "OBJECT":
        return
    if obj.parent is not None:
        world = obj.matrix_world.copy()
        obj.parent = None
        obj.matrix_basis = world
    obj.parent = armature
    obj.parent_type = "OBJECT"
    obj.matrix_parent_inverse = armature.matrix_world.inverted()

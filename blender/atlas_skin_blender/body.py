"""The selected meshes as one body: their vertices at the armature's rest pose, in the
armature's space with glTF's axes (see `axes.py`), and their triangles, numbered across
all meshes."""
from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np

from .axes import to_gltf_axes


class BodyError(Exception):
    """Meshes atlas-skin cannot read as one body (the message names the mesh)."""


@dataclass
class Body:
    """positions: (V, 3) float64 positions in the armature's space, glTF's axes;
    triangles: (F, 3) int64 indices into positions; ranges: for each mesh object,
    (object, first, end) of its vertices in positions (its vertex i is row first + i);
    warnings: what was read differently from what the user sees."""

    positions: np.ndarray
    triangles: np.ndarray
    ranges: list
    warnings: list = field(default_factory=list)


@contextmanager
def rest_state(armature, meshes):
    """The scene with the armature in its rest position and the meshes' Armature modifiers
    switched off, restored afterwards: the meshes as they are before any skinning, whatever
    the current pose and whatever an earlier run bound them to (so a second run reads the
    same input as the first)."""
    pose_position = armature.data.pose_position
    switched = [
        m for obj in meshes for m in obj.modifiers if m.type == "ARMATURE" and m.show_viewport
    ]
    armature.data.pose_position = "REST"
    for modifier in switched:
        modifier.show_viewport = False
    try:
        yield
    finally:
        for modifier in switched:
            modifier.show_viewport = True
        armature.data.pose_position = pose_position


def read_body(depsgraph, armature, meshes, progress=lambda: None):
    """Reads `meshes` (mesh objects) evaluated by `depsgraph` into the space of `armature`
    (an armature object), to be called inside `rest_state`. A mesh whose modifiers keep
    its vertices is read as evaluated (shape keys and deforming modifiers applied), as
    Blender's own automatic weights read it; one whose modifiers change its vertex count
    is read without them, with a warning, since its weights belong to the mesh's own
    vertices. Calls `progress` after each mesh."""
    check_distinct_data(meshes)
    positions, triangles, ranges, warnings = [], [], [], []
    first = 0
    for obj in meshes:
        evaluated = obj.evaluated_get(depsgraph)
        mesh = evaluated.to_mesh()
        try:
            count = len(obj.data.vertices)
            if len(mesh.vertices) != count:
                warnings.append(
                    f"{obj.name}: its modifiers ({modifier_names(obj)}) change the vertex count "
                    f"({len(mesh.vertices)} evaluated, {count} in the mesh); weighted without them"
                )
                mesh = obj.data
            local, tris = mesh_arrays(mesh)
        finally:
            evaluated.to_mesh_clear()
        to_armature = armature_from_object(armature, obj, evaluated)
        if to_armature.determinant() < 0.0:
            tris = tris[:, ::-1]  # a mirroring transform turns the surface inside out
        positions.append(to_gltf_axes(local, to_armature))
        triangles.append(tris + first)
        ranges.append((obj, first, first + count))
        first += count
        progress()
    if not any(len(t) for t in triangles):
        raise BodyError("the selected meshes have no faces")
    return Body(np.concatenate(positions), np.concatenate(triangles), ranges, warnings)


def armature_from_object(armature, obj, evaluated):
    """The transform from the space of `obj` (evaluated: its evaluated copy) to the
    armature's. For a child of the armature, P · B (its parent inverse and basis, the world
    A · P · B without the round trip through A); otherwise A⁻¹ · W (W its world). Binding
    makes a mesh such a child with P = A⁻¹ and B kept (`binding.py`), so a second run
    reads the same numbers, bit for bit, as the first."""
    if obj.parent == armature and obj.parent_type == "OBJECT" and not obj.constraints:
        return obj.matrix_parent_inverse @ evaluated.matrix_basis
    return armature.matrix_world.inverted() @ evaluated.matrix_world


def mesh_arrays(mesh):
    """(V, 3) float64 vertex positions and (F, 3) int64 triangles of a Blender mesh."""
    local = np.empty(len(mesh.vertices) * 3, dtype=np.float64)
    mesh.vertices.foreach_get("co", local)
    mesh.calc_loop_triangles()
    tris = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int64)
    mesh.loop_triangles.foreach_get("vertices", tris)
    return local.reshape(-1, 3), tris.reshape(-1, 3)


def modifier_names(obj):
    """The object's modifiers other than Armature, for messages."""
    return ", ".join(m.name for m in obj.modifiers if m.type != "ARMATURE")


def check_distinct_data(meshes):
    """Vertex groups live in the mesh data: two objects sharing one mesh cannot get the
    weights of two places."""
    owners = {}
    for obj in meshes:
        other = owners.setdefault(obj.data.name, obj)
        if other is not obj:
            raise BodyError(
                f"'{other.name}' and '{obj.name}' share the mesh '{obj.data.name}' "
                "(linked duplicates): make one single user (Object > Relations) first"
            )

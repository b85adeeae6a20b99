"""Checks of skinned characters in Blender shared by the add-on's test scripts: glTF
import, weights read back from vertex groups, validity, comparison with `atlas-skin skin`,
posing. Import after setting BLENDER_USER_RESOURCES (bpy reads it on import)."""
import subprocess

import bpy
import numpy as np
from mathutils import Matrix, Quaternion, kdtree

TOLERANCE = 1e-5

# The add-on's weights against those of `atlas-skin skin` on the same file. The bones pass
# through Blender's edit bones (head, tail and roll in float32): on CesiumMan their frames
# come back within 1.4e-6 of the file's.
CLI_TOLERANCE = 1e-4


def empty_scene():
    """An empty file, the preferences (and so the enabled add-ons) kept."""
    bpy.ops.wm.read_homefile(use_empty=True)


def import_character(path):
    """Empty scene, Blender's glTF import; (armature, its skinned meshes by name)."""
    empty_scene()
    return import_more(path)


def import_more(path):
    """Blender's glTF import into the scene as it is; (the new armature, its meshes by
    name), animations cleared and every bone at rest."""
    before = set(bpy.data.objects)
    bpy.ops.import_scene.gltf(filepath=path)
    armatures = [o for o in bpy.data.objects if o not in before and o.type == "ARMATURE"]
    assert len(armatures) == 1, f"{path}: {len(armatures)} armatures"
    armature = armatures[0]
    meshes = sorted(
        (o for o in bpy.data.objects if o.type == "MESH" and o.parent == armature),
        key=lambda o: o.name,
    )
    assert meshes, f"{path}: no mesh under the armature"
    for obj in bpy.data.objects:
        obj.animation_data_clear()
    for pose_bone in armature.pose.bones:
        pose_bone.matrix_basis.identity()
    return armature, meshes


def strip_weights(meshes, unparent=False):
    """Removes every vertex group and modifier; with unparent, also the parent (the mesh
    staying where it is)."""
    for obj in meshes:
        obj.vertex_groups.clear()
        obj.modifiers.clear()
        if unparent:
            world = obj.matrix_world.copy()
            obj.parent = None
            obj.matrix_world = world


def restore_file_numbers(path, armature, meshes):
    """Gives the imported vertices and bones the numbers of the file, as `atlas_skin.load`
    reads them for `atlas-skin skin` (a bone's head at its joint, its frame the joint's bind
    frame: its axes give leaf joints their direction); returns how far Blender's importer
    had moved the vertices and heads (the largest distance, in the file's units).

    Blender's glTF importer skins each vertex into the bind pose in float32
    (io_scene_gltf2, `skin_into_bind_pose`) and rebuilds the bones from the joint
    matrices: on CesiumMan, vertices move by up to 5e-7 and joints by 3e-7. The method is
    not continuous everywhere (a vertex on a cut plane goes to one side or the other), so
    the comparison with the command line is made on the file's own numbers. Each vertex
    and bone is matched to the file's nearest (within 1e-5); the meshes must lie in the
    armature's space unmoved (the add-on then reads exactly these numbers).
    """
    import atlas_skin

    character = atlas_skin.load(path)
    to_blender = np.array(((1.0, 0.0, 0.0), (0.0, 0.0, -1.0), (0.0, 1.0, 0.0)))
    file_positions = character["positions"].astype(np.float64) @ to_blender.T
    file_joints = character["joint_positions"].astype(np.float64) @ to_blender.T
    to_blender_4 = np.eye(4)
    to_blender_4[:3, :3] = to_blender
    file_frames = to_blender_4 @ np.linalg.inv(character["inverse_bind"].astype(np.float64))
    tree = kdtree.KDTree(len(file_positions))
    for i, p in enumerate(file_positions):
        tree.insert(p, i)
    tree.balance()
    moved = 0.0
    for obj in meshes:
        identity = Matrix.Identity(4)
        if obj.parent == armature:
            unmoved = obj.matrix_parent_inverse @ obj.matrix_basis == identity
        else:
            unmoved = obj.matrix_world == identity == armature.matrix_world
        assert unmoved, f"{obj.name} is not in the armature's space unmoved"
        for v in obj.data.vertices:
            _, i, distance = tree.find(v.co)
            assert distance < 1e-5, f"{path}: vertex {v.index} of {obj.name} is not in the file"
            moved = max(moved, distance)
            v.co = file_positions[i]
    bpy.context.view_layer.objects.active = armature
    bpy.ops.object.mode_set(mode="EDIT")
    for bone in armature.data.edit_bones:
        distance = np.linalg.norm(file_joints - np.array(bone.head), axis=1)
        assert distance.min() < 1e-5, f"{path}: bone {bone.name} is no joint of the file"
        moved = max(moved, distance.min())
        # The frame's axes without scale; EditBone.matrix keeps the bone's length and sets
        # its head, its direction (+Y) and its roll.
        frame = file_frames[distance.argmin()].copy()
        frame[:3, :3] /= np.linalg.norm(frame[:3, :3], axis=0)
        bone.matrix = Matrix(frame.tolist())
        bone.head = file_joints[distance.argmin()]
    bpy.ops.object.mode_set(mode="OBJECT")
    return moved


def select(armature, meshes):
    """Selects the meshes and the armature, the armature active (as Ctrl+P wants them)."""
    bpy.ops.object.select_all(action="DESELECT")
    for obj in [armature, *meshes]:
        obj.select_set(True)
    bpy.context.view_layer.objects.active = armature


def run_operator(armature, meshes, undo=False, **options):
    select(armature, meshes)
    return bpy.ops.object.parent_atlas_skin("EXEC_DEFAULT", undo, **options)


def bone_weights(obj, bone_names):
    """(V, J) float64 weights of obj's groups named after bone_names."""
    column = {g.index: bone_names.index(g.name) for g in obj.vertex_groups if g.name in bone_names}
    weights = np.zeros((len(obj.data.vertices), len(bone_names)))
    for v in obj.data.vertices:
        for g in v.groups:
            if g.group in column:
                weights[v.index, column[g.group]] = g.weight
    return weights


def deforming_names(armature):
    return [b.name for b in armature.data.bones if b.use_deform]


def world_positions(meshes):
    """(V, 3) evaluated world positions of all meshes, one after the other."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    rows = []
    for obj in meshes:
        evaluated = obj.evaluated_get(depsgraph)
        mesh = evaluated.to_mesh()
        local = np.empty(len(mesh.vertices) * 3)
        mesh.vertices.foreach_get("co", local)
        m = np.array(evaluated.matrix_world)
        rows.append(local.reshape(-1, 3) @ m[:3, :3].T + m[:3, 3])
        evaluated.to_mesh_clear()
    return np.concatenate(rows)


def cli_weights(atlas_skin, path, out, *options):
    """The weights `atlas-skin skin` writes for `path`, read back by Blender's importer:
    {mesh object name: (V, J) weights}, columns as deforming_names of the armature."""
    subprocess.run([atlas_skin, "skin", path, "-o", out, *options], check=True, capture_output=True)
    armature, meshes = import_character(out)
    names = deforming_names(armature)
    return names, {o.name: (bone_weights(o, names), world_positions([o])) for o in meshes}


def check_groups(name, meshes, names, max_influences=4):
    for obj in meshes:
        w = bone_weights(obj, names)
        counts = (w > 0).sum(axis=1)
        assert counts.min() >= 1, f"{name}/{obj.name}: a vertex in no bone group"
        assert counts.max() <= max_influences, f"{name}/{obj.name}: {counts.max()} influences"
        error = np.abs(w.sum(axis=1) - 1).max()
        assert error < TOLERANCE, f"{name}/{obj.name}: weights sum to 1 ± {error}"
        assert set(names) <= {g.name for g in obj.vertex_groups}, "a deforming bone has no group"


def check_matches_cli(name, meshes, names, cli_names, cli):
    assert names == cli_names, f"{name}: bones {names} against the CLI's {cli_names}"
    worst = 0.0
    for obj in meshes:
        theirs, positions = cli[obj.name]
        ours = bone_weights(obj, names)
        assert ours.shape == theirs.shape, f"{name}/{obj.name}: {ours.shape} against {theirs.shape}"
        assert np.abs(world_positions([obj]) - positions).max() < 1e-6, "vertices differ"
        worst = max(worst, np.abs(ours - theirs).max())
    assert worst <= CLI_TOLERANCE, f"{name}: weights differ from atlas-skin skin's by {worst}"
    return worst


def descendants(armature, bone_name, names):
    bone = armature.data.bones[bone_name]
    return [names.index(b.name) for b in [bone, *bone.children_recursive] if b.name in names]


def check_pose(name, armature, meshes, names):
    """Each deforming bone turned 30 degrees: vertices without weight in its subtree stay,
    its own part (weight 1 in the subtree) moves."""
    weights = np.concatenate([bone_weights(o, names) for o in meshes])
    rest = world_positions(meshes)
    diagonal = np.linalg.norm(rest.max(axis=0) - rest.min(axis=0))
    moved_parts = 0
    for bone_name in names:
        pose_bone = armature.pose.bones[bone_name]
        pose_bone.rotation_mode = "QUATERNION"
        pose_bone.rotation_quaternion = Quaternion((1.0, 0.0, 0.0), np.radians(30))
        bpy.context.view_layer.update()
        moved = np.linalg.norm(world_positions(meshes) - rest, axis=1)
        pose_bone.rotation_quaternion = Quaternion()
        subtree = weights[:, descendants(armature, bone_name, names)].sum(axis=1)
        outside = moved[subtree == 0]
        assert outside.size == 0 or outside.max() < 1e-5 * diagonal, (
            f"{name}: turning {bone_name} moves vertices it does not weight "
            f"({(outside >= 1e-5 * diagonal).sum()}, "
            f"by up to {outside.max() / diagonal:.2g} diagonals)"
        )
        part = moved[subtree > 1 - 1e-6]
        if part.size:
            share = (part > 1e-4 * diagonal).mean()
            assert share > 0.9, f"{name}: turning {bone_name} moves {share:.0%} of its part"
            moved_parts += 1
    bpy.context.view_layer.update()
    assert moved_parts >= len(names) // 2, f"{name}: only {moved_parts} bones move a part"


def groups_snapshot(meshes):
    """Everything the operator may change on the meshes, with their world matrices."""
    bpy.context.view_layer.update()
    return {
        o.name: (
            [g.name for g in o.vertex_groups],
            [[(g.group, g.weight) for g in v.groups] for v in o.data.vertices],
            [(m.type, m.object.name if m.type == "ARMATURE" else "") for m in o.modifiers],
            o.parent.name if o.parent else None,
            [tuple(r) for r in o.matrix_world],
        )
        for o in meshes
    }



"""Helpers shared by the Blender scripts of this folder."""
import bpy


def the_armature():
    """The only armature of the scene (an error otherwise)."""
    armatures = [o for o in bpy.data.objects if o.type == "ARMATURE"]
    if len(armatures) != 1:
        raise SystemExit(f"expected one armature, found {len(armatures)}")
    return armatures[0]


def empty_scene():
    """Blender's factory settings without the default cube, camera and light."""
    bpy.ops.wm.read_factory_settings(use_empty=True)


def replace_weights_by_bone_heat(armature):
    """Blender's automatic weights ("With Automatic Weights", bone heat) on every mesh
    parented to `armature`, after removing their vertex groups and modifiers. Returns the
    meshes and the seconds of the solve alone. Blender reports a failed solve ("Bone Heat
    Weighting: failed to find solution for one or more bones") on its standard output and
    goes on, leaving vertices without weights."""
    import time

    meshes = [o for o in bpy.data.objects if o.type == "MESH" and o.parent == armature]
    if not meshes:
        raise SystemExit("no mesh is parented to the armature")
    bpy.ops.object.select_all(action="DESELECT")
    for mesh in meshes:
        mesh.vertex_groups.clear()
        mesh.modifiers.clear()
        mesh.select_set(True)
    armature.select_set(True)
    bpy.context.view_layer.objects.active = armature
    start = time.perf_counter()
    bpy.ops.object.parent_set(type="ARMATURE_AUTO")
    return meshes, time.perf_counter() - start

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

"""Imports a skinned glTF with Blender (the `bpy` package), replaces its weights by
Blender's automatic weights (bone heat, "With Automatic Weights") and exports two glbs:
one with the bone names Blender gave (an unnamed glTF node 2 becomes `Node_2`) and one
with every bone renamed lowercase without punctuation (`node2`), so that a tool reading
the original finds the same names.

Usage: python bone_heat.py INPUT.glb BLENDER_NAMES.glb PLAIN_NAMES.glb
"""
import sys

import bpy
from scene import empty_scene, the_armature


def export(path):
    bpy.ops.export_scene.gltf(filepath=path, export_format="GLB", export_animations=False)


def main():
    source, blender_names, plain_names = sys.argv[1:4]
    empty_scene()
    bpy.ops.import_scene.gltf(filepath=source)
    armature = the_armature()
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
    bpy.ops.object.parent_set(type="ARMATURE_AUTO")
    export(blender_names)
    for bone in armature.data.bones:
        bone.name = "".join(c for c in bone.name.lower() if c.isalnum())
    export(plain_names)


main()

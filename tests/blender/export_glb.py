"""Imports an FBX with Blender (the `bpy` package) and exports the scene as a glTF binary
with Blender's exporter, in metres: +Y up as glTF has it, or with --z-up Blender's own
+Z up (the exporter's "+Y Up" off). Animations are left out.

Usage: python export_glb.py INPUT.fbx OUT.glb [--z-up]
"""
import sys

import bpy
from scene import empty_scene


def main():
    source, out = sys.argv[1:3]
    z_up = "--z-up" in sys.argv[3:]
    empty_scene()
    bpy.ops.import_scene.fbx(filepath=source)
    result = bpy.ops.export_scene.gltf(
        filepath=out, export_format="GLB", export_animations=False, export_yup=not z_up
    )
    if result != {"FINISHED"}:
        raise SystemExit(f"export of {source} failed: {result}")


main()

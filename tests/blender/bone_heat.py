"""Imports a skinned glTF with Blender (the `bpy` package), replaces its weights by
Blender's automatic weights (bone heat, "With Automatic Weights") and exports them as a glb
with the bone names Blender gave (an unnamed glTF node 2 becomes `Node_2`); with a third
path, also one with every bone renamed lowercase without punctuation (`node2`), so that a
tool reading the original finds the same names. Prints how many vertices bone heat left
without weights.

`--bone-heuristic` is the glTF importer's choice of bone tails (BLENDER, TEMPERANCE,
FORTUNE; Blender's default is BLENDER). Bone heat weighs each vertex by its distance to
the bones' segments, so the tails change the weights: TEMPERANCE reproduces the heat rows
of ../shared/data/bench/BASELINES.md (scripts/heat-same-poses).

Usage: python bone_heat.py INPUT.glb BLENDER_NAMES.glb [PLAIN_NAMES.glb]
       [--bone-heuristic H]
"""
import argparse

import bpy
from scene import empty_scene, replace_weights_by_bone_heat, the_armature


def export(path):
    bpy.ops.export_scene.gltf(filepath=path, export_format="GLB", export_animations=False)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("source")
    parser.add_argument("blender_names")
    parser.add_argument("plain_names", nargs="?")
    parser.add_argument("--bone-heuristic", default="BLENDER")
    args = parser.parse_args()
    empty_scene()
    bpy.ops.import_scene.gltf(filepath=args.source, bone_heuristic=args.bone_heuristic)
    armature = the_armature()
    meshes, _ = replace_weights_by_bone_heat(armature)
    unweighted = sum(
        1 for m in meshes for v in m.data.vertices if not any(g.weight > 0 for g in v.groups)
    )
    # Read by scripts/heat-same-poses: the glTF exporter binds such vertices to a joint of
    # its own (`neutral_bone`), which the character's skeleton does not have.
    print(f"unweighted vertices: {unweighted}")
    export(args.blender_names)
    if args.plain_names:
        for bone in armature.data.bones:
            bone.name = "".join(c for c in bone.name.lower() if c.isalnum())
        export(args.plain_names)


main()

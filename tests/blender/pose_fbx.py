"""Imports an FBX with Blender (the `bpy` package), poses its armature and prints the posed
vertex positions of every skinned mesh as JSON, in glTF's axes (+Y up), metres.

Usage: python pose_fbx.py INPUT.fbx ROTATIONS.json OUT.json

Every vertex keeps its 4 largest weights (Blender's "Limit Total"), as atlas-skin's `pose`
and glTF viewers do.

ROTATIONS.json maps bone names to quaternions [x, y, z, w] in glTF's axes: the rotation of
that bone about its own head, in world axes, applied after its parent's (a pose that does
not depend on how a tool orients its bones). Bones not listed keep their rest pose.
"""
import json
import sys

import bpy
from scene import empty_scene, the_armature
from mathutils import Matrix, Quaternion

# glTF (x, y, z) -> Blender (x, -z, y) and back.
TO_BLENDER = Matrix(((1, 0, 0), (0, 0, -1), (0, 1, 0)))


def main():
    source, rotations_path, out = sys.argv[1:4]
    with open(rotations_path) as f:
        rotations = json.load(f)
    empty_scene()
    bpy.ops.import_scene.fbx(filepath=source)
    armature = the_armature()
    # An imported animation would override the pose on every evaluation.
    for obj in bpy.data.objects:
        obj.animation_data_clear()
    for pose_bone in armature.pose.bones:
        pose_bone.matrix_basis = Matrix.Identity(4)
    world = armature.matrix_world
    world_inv = world.inverted()
    bones = armature.data.bones
    delta = {}  # bone name -> world-space skinning matrix S
    for bone in sorted(bones, key=lambda b: len(b.parent_recursive)):
        x, y, z, w = rotations.get(bone.name, [0.0, 0.0, 0.0, 1.0])
        q = (TO_BLENDER @ Quaternion((w, x, y, z)).to_matrix() @ TO_BLENDER.transposed())
        head = world @ bone.head_local
        about_head = (Matrix.Translation(head) @ q.to_4x4() @ Matrix.Translation(-head))
        parent = delta[bone.parent.name] if bone.parent else Matrix.Identity(4)
        delta[bone.name] = parent @ about_head
        pose_bone = armature.pose.bones[bone.name]
        pose_bone.matrix = world_inv @ delta[bone.name] @ world @ bone.matrix_local
        bpy.context.view_layer.update()
    for obj in bpy.data.objects:
        if obj.type == "MESH" and obj.vertex_groups:
            bpy.context.view_layer.objects.active = obj
            bpy.ops.object.vertex_group_limit_total(group_select_mode="ALL", limit=4)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    meshes = []
    for obj in bpy.data.objects:
        if obj.type != "MESH":
            continue
        evaluated = obj.evaluated_get(depsgraph)
        mesh = evaluated.to_mesh()
        to_gltf = TO_BLENDER.transposed()
        positions = [list(to_gltf @ (evaluated.matrix_world @ v.co)) for v in mesh.vertices]
        meshes.append({"name": obj.data.name, "object": obj.name, "positions": positions})
        evaluated.to_mesh_clear()
    with open(out, "w") as f:
        json.dump({"meshes": meshes, "bones": [b.name for b in bones]}, f)


main()

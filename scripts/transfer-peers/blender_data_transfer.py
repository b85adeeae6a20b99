"""Blender's Data Transfer of vertex groups ("Nearest Face Interpolated", the usual way to
weight clothes from a body in Blender) on the jobs of scripts/benchmark-transfer, through
the `bpy` package: the source mesh gets one vertex group per joint with its weights, the
target a Data Transfer modifier (vertex data, vertex groups, all layers by name, mapping
POLYINTERP_NEAREST), applied; the target's groups are read back.

Jobs and answers as in reference_transfer.py ("seconds": the modifier's evaluation).

Usage: python blender_data_transfer.py JOB.json OUT.json [JOB.json OUT.json ...]
"""
import json
import sys
import time

import bpy


def mesh_object(name, positions, triangles):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(positions, [], triangles)
    mesh.validate()
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def run(job):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    src, tgt = job["source"], job["target"]
    source = mesh_object("source", src["positions"], src["triangles"])
    target = mesh_object("target", tgt["positions"], tgt["triangles"])
    joints = len(src["weights"][0]) if src["weights"] else 0
    groups = [source.vertex_groups.new(name=f"j{j}") for j in range(joints)]
    for v, row in enumerate(src["weights"]):
        for j, w in enumerate(row):
            if w > 0:
                groups[j].add([v], w, "REPLACE")
    for j in range(joints):
        target.vertex_groups.new(name=f"j{j}")
    modifier = target.modifiers.new("transfer", "DATA_TRANSFER")
    modifier.object = source
    modifier.use_vert_data = True
    modifier.data_types_verts = {"VGROUP_WEIGHTS"}
    modifier.vert_mapping = "POLYINTERP_NEAREST"
    modifier.layers_vgroup_select_src = "ALL"
    modifier.layers_vgroup_select_dst = "NAME"
    bpy.context.view_layer.objects.active = target
    start = time.perf_counter()
    bpy.ops.object.modifier_apply(modifier=modifier.name)
    seconds = time.perf_counter() - start
    index = {g.index: int(g.name[1:]) for g in target.vertex_groups}
    rows = [[0.0] * joints for _ in tgt["positions"]]
    for v in target.data.vertices:
        for g in v.groups:
            rows[v.index][index[g.group]] = g.weight
    return rows, seconds


def main():
    args = sys.argv[1:]
    for job_path, out_path in zip(args[0::2], args[1::2]):
        with open(job_path) as f:
            job = json.load(f)
        try:
            weights, seconds = run(job)
            error = None
        except Exception as e:
            weights, seconds, error = None, 0.0, f"{type(e).__name__}: {e}"
        with open(out_path, "w") as f:
            json.dump({"weights": weights, "seconds": seconds, "error": error}, f)


main()

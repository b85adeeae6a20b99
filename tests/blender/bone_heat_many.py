"""Blender's bone heat ("With Automatic Weights") on many glTF files in one Blender (the
`bpy` package): for each (source, output) pair of the JSON list given, imports the source
(TEMPERANCE bone tails, with which ../shared/data/bench/BASELINES.md's heat rows are
reproduced: docs/heat-same-poses.md), replaces its weights by bone heat, and exports the
output glb when bone heat weighted every vertex. Prints one JSON line per pair:
{"source", "status": "ok" | "failed", "reason", "seconds"}. A failed solve ("Bone Heat
Weighting: failed to find solution for one or more bones", which Blender prints on the
process's standard output) or vertices left without weights count as failed: the glTF
exporter would bind those to a joint of its own (`neutral_bone`) that no pose places.

Usage: python bone_heat_many.py PAIRS.json   (run by scripts/bone-heat)
"""
import json
import os
import sys
import tempfile
import time

import bpy
from scene import empty_scene, replace_weights_by_bone_heat, the_armature

HEAT_FAILED = "Bone Heat Weighting: failed to find solution"


def heat(source, output):
    """Bone heat on `source`, exported to `output`: None, or why there is no result."""
    empty_scene()
    bpy.ops.import_scene.gltf(filepath=source, bone_heuristic="TEMPERANCE")
    meshes, _ = replace_weights_by_bone_heat(the_armature())
    unweighted = sum(
        1 for m in meshes for v in m.data.vertices if not any(g.weight > 0 for g in v.groups)
    )
    if unweighted:
        return f"left {unweighted} vertices without weights"
    partial = output + ".partial.glb"
    bpy.ops.export_scene.gltf(filepath=partial, export_format="GLB", export_animations=False)
    os.replace(partial, output)
    return None


def main():
    with open(sys.argv[1]) as f:
        pairs = json.load(f)
    # Blender's C code prints the failed solve on file descriptor 1: each character's
    # output goes to a file of its own, read after, and our lines to the saved descriptor.
    out = os.fdopen(os.dup(1), "w")
    for source, output in pairs:
        start = time.perf_counter()
        with tempfile.TemporaryFile(mode="w+") as captured:
            sys.stdout.flush()
            saved = os.dup(1)
            os.dup2(captured.fileno(), 1)
            try:
                reason = heat(source, output)
            except (Exception, SystemExit) as e:  # one broken file must not stop the rest
                reason = f"Blender: {e}"
            finally:
                sys.stdout.flush()
                os.dup2(saved, 1)
                os.close(saved)
            captured.seek(0)
            if HEAT_FAILED in captured.read():
                reason = "failed to find a solution for one or more bones"
        record = {
            "source": source,
            "status": "failed" if reason else "ok",
            "reason": reason or "",
            "seconds": round(time.perf_counter() - start, 3),
        }
        out.write(json.dumps(record) + "\n")
        out.flush()


main()

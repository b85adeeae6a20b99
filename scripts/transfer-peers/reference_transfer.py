"""Runs the reference implementation of *Robust Skin Weights Transfer via Weight
Inpainting* (Abdrashitov et al. 2023; its authors' code, read from
../shared/peers/robust-skin-weights-transfer/src, never copied) on the jobs that
scripts/benchmark-transfer writes, the way its own example runs it: per-vertex normals
(igl), closest point matching (§3.1), inpainting (§3.2, igl.min_quad_with_fixed), then its
optional smoothing (§3.3, 10 steps, alpha 0.2). It solves one mesh at a time and fails
on a mesh with a piece that has no matched vertex (its system is singular), so it is run
piece by piece (connected components of the target, as a user would run it on each
garment), and a piece it cannot solve keeps the closest point weights of its matching
step (counted in the answer's "unsolved_pieces").

Each job is a JSON file {"source": {"positions", "triangles", "weights"}, "target":
{"positions", "triangles"}, "distance", "angle_degrees"}; the answer, written to the path
given beside it, is {"weights": rows or null, "seconds": time of matching + inpainting +
smoothing, "error": null or a message, "unsolved_pieces": count}. The matching distance is the one atlas-skin uses
(given in the job), so that the two differ in their method only.

Usage: python reference_transfer.py PEER_SRC JOB.json OUT.json [JOB.json OUT.json ...]
"""
import json
import sys
import time

import numpy as np
import scipy.sparse.csgraph


def run(utils, igl, job):
    src, tgt = job["source"], job["target"]
    v1 = np.asarray(src["positions"], dtype=np.float64)
    f1 = np.asarray(src["triangles"], dtype=np.int64)
    w1 = np.asarray(src["weights"], dtype=np.float64)
    v2 = np.asarray(tgt["positions"], dtype=np.float64)
    f2 = np.asarray(tgt["triangles"], dtype=np.int64)
    # The example's preparation: unreferenced vertices removed (mapped back below).
    v1r, f1r, _, j1 = igl.remove_unreferenced(v1, f1)
    w1r = w1[j1]
    v2r, f2r, _, j2 = igl.remove_unreferenced(v2, f2)
    start = time.perf_counter()
    n1 = igl.per_vertex_normals(v1r, f1r)
    d = job["distance"]
    out = np.zeros((v2.shape[0], w1.shape[1]))
    # The closest point weights of every vertex, for the pieces it cannot solve.
    n2 = igl.per_vertex_normals(v2r, f2r)
    _, copied = utils.find_matches_closest_surface(
        v1r, f1r, n1, v2r, f2r, n2, w1r, d * d, job["angle_degrees"]
    )
    _, labels = scipy.sparse.csgraph.connected_components(igl.adjacency_matrix(f2r), directed=False)
    face_piece = labels[f2r[:, 0]]
    unsolved = 0
    for piece in np.unique(face_piece):
        faces = f2r[face_piece == piece]
        vertices = np.unique(faces)
        try:
            vp, fp, _, jp = igl.remove_unreferenced(v2r, faces)
            np2 = igl.per_vertex_normals(vp, fp)
            matched, w2 = utils.find_matches_closest_surface(
                v1r, f1r, n1, vp, fp, np2, w1r, d * d, job["angle_degrees"]
            )
            inpainted, ok = utils.inpaint(vp, fp, w2, matched)
            ok = ok and np.all(np.isfinite(inpainted))
            if ok:
                smoothed, _ = utils.smooth(
                    vp, fp, inpainted, matched, d, num_smooth_iter_steps=10, smooth_alpha=0.2
                )
                out[j2[jp]] = smoothed
        except ValueError:  # libigl refuses a piece of one or two faces
            ok = False
        if not ok:
            unsolved += 1
            out[j2[vertices]] = copied[vertices]
    seconds = time.perf_counter() - start
    if not np.all(np.isfinite(out)):
        return None, seconds, "non-finite weights", unsolved
    return out.tolist(), seconds, None, unsolved


def main():
    sys.path.insert(0, sys.argv[1])
    import igl
    import utils

    args = sys.argv[2:]
    for job_path, out_path in zip(args[0::2], args[1::2]):
        with open(job_path) as f:
            job = json.load(f)
        try:
            weights, seconds, error, unsolved = run(utils, igl, job)
        except Exception as e:  # the reference fails on some inputs: recorded, not fatal
            weights, seconds, error, unsolved = None, 0.0, f"{type(e).__name__}: {e}", 0
        with open(out_path, "w") as f:
            json.dump({"weights": weights, "seconds": seconds, "error": error, "unsolved_pieces": unsolved}, f)


main()

"""Type stubs of atlas_skin's native module (crates/atlas-skin-py/src/lib.rs)."""

from os import PathLike
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, TypedDict, Union

import numpy as np
import numpy.typing as npt
from typing_extensions import Unpack

__version__: str

StrPath = Union[str, "PathLike[str]"]

class QualityGateError(Exception):
    """The quality gate (``fail_on``) rejected the character.

    - ``reasons``: why, one ``"CONDITION: cause"`` per cause (e.g. ``"soft-joints: 2 soft
      joint(s) carry no weight: LHandEX, RHandEX"``);
    - ``report``: the JSON report (a dict); its ``quality`` holds ``fail_on``,
      ``rejected``, ``reasons`` and the joints ``soft-joints`` and ``unweighted-joints``
      name;
    - ``output``: the skinned glb written under its rejected name
      (``OUT.rejected.glb``) when ``keep_rejected`` asked for it, else None.
    """

    reasons: List[str]
    report: Dict[str, Any]
    output: Optional[str]

FloatArray = npt.ArrayLike
"""float32 or float64 values (a numpy array or anything ``numpy.asarray`` takes)."""
IntArray = npt.ArrayLike
"""integer values of any integer dtype."""

class MethodOptions(TypedDict, total=False):
    """The method's options, taken as keyword arguments by ``compute_weights``,
    ``skin_file`` and ``batch`` (the flags of ``atlas-skin skin``). Each left out or
    ``None`` keeps the settings file's value, else the method's default; an unknown name
    raises ``TypeError``.

    - ``overlap``: overlap half-width as a multiple of each boundary's diameter (default
      0.5, the paper's): small is quasi-rigid, large is soft (``--overlap``).
    - ``overlap_joints``: the overlap factor of single joints, by name
      (``--overlap-joint NAME=F``).
    - ``blend``: ``"pou"`` (default: the normalised partition of unity, continuous
      everywhere) or ``"paper"`` (the paper's Eq. 1) (``--blend``).
    - ``binding``: ``"smooth"`` (default: blended weights) or ``"rigid"`` (one joint per
      vertex, weight 1, for a character its artist would bind rigidly: the same cuts, each
      vertex moving with the deepest joint whose branch holds more than half of its blended
      weights) (``--binding``).
    - ``force``: joint names given a boundary (a cut) even where the rules would not
      (``--force``).
    - ``forbid``: joint names given no boundary: their part moves with the parent's
      (``--forbid``).
    - ``max_influences``: influences kept per vertex, the largest, renormalised (1..=32,
      default 4) (``--max-influences``).
    - ``config``: a settings file (``--config``: JSON, any subset of ``decompose``,
      ``overlap`` {``factor``, ``per_joint``}, ``blend``, ``binding``,
      ``max_influences``, ``fail_on``), which the options above override.
    - ``fail_on``: the quality gate (``--fail-on``): conditions, as a list of names or one
      string of names separated by commas, on which the character is rejected:
      ``"warnings"`` (any warning), ``"input"``, ``"mesh"``, ``"placement"``,
      ``"skeleton"``, ``"weights"`` (a warning of that topic: the report's
      ``warning_topics``), ``"fallback"`` (a vertex weighted by a fallback),
      ``"soft-joints"`` (a soft joint that carries no weight), ``"unweighted-joints"`` (a
      joint given a boundary that carries no weight). ``compute_weights`` and
      ``skin_file`` raise ``QualityGateError``; ``batch`` records the file as
      ``"rejected"``. An unknown name raises ``ValueError``.
    """

    overlap: Optional[float]
    overlap_joints: Optional[Mapping[str, float]]
    blend: Optional[str]
    binding: Optional[str]
    force: Optional[Sequence[str]]
    forbid: Optional[Sequence[str]]
    max_influences: Optional[int]
    config: Optional[StrPath]
    fail_on: Optional[Union[str, Sequence[str]]]

def compute_weights(
    vertices: FloatArray,
    triangles: IntArray,
    joint_positions: FloatArray,
    parents: IntArray,
    *,
    tails: Optional[FloatArray] = None,
    inverse_bind: Optional[FloatArray] = None,
    names: Optional[Sequence[str]] = None,
    end_joints: Optional[Sequence[int]] = None,
    **options: Unpack[MethodOptions],
) -> Tuple[npt.NDArray[np.uint32], npt.NDArray[np.float32], Dict[str, Any]]:
    """Skinning weights of a mesh for a skeleton (the method of ``atlas-skin skin``).

    Arrays (the mesh and the skeleton in one space, the bind pose; any unit):

    - ``vertices``: ``(V, 3)`` float32 or float64 positions, as stored (seams may be
      split: coincident vertices are welded for the method and get equal weights).
    - ``triangles``: ``(F, 3)`` integer vertex indices, each in ``0..V``.
    - ``joint_positions``: ``(J, 3)`` floats, the joints' bind positions (a Blender bone's
      head).
    - ``parents``: ``(J,)`` integers, the parent joint of each joint, ``-1`` for a root.

    Options:

    - ``tails``: ``(J, 3)`` floats, the far end of each joint's bone (a Blender bone's
      tail); a row of NaN means none. Only leaf joints use it: their bone runs from the
      joint to its tail (without one, it continues the parent's bone by half its length).
    - ``inverse_bind``: ``(J, 4, 4)`` floats, the inverse of each joint's bind frame
      (``M[row, column]`` acting on column vectors, as ``load`` returns them); their
      translations must place the joints at ``joint_positions``. The weights do not depend
      on the frames' rotations; without them every frame is the world's.
    - ``names``: ``J`` unique joint names (default ``joint0``, ``joint1``, ...): the names
      that ``overlap_joints``, ``force`` and ``forbid`` use, and that the report shows.
    - ``end_joints``: joints that move nothing (the leaves of a TGF skeleton, libigl's
      handles): given no boundary unless forced.
    - ``**options``: the method's options (``MethodOptions``: ``overlap``,
      ``overlap_joints``, ``blend``, ``binding``, ``force``, ``forbid``, ``max_influences``,
      ``config``, ``fail_on``).

    Returns ``(indices, weights, report)``: ``(V, K)`` uint32 joint indices and ``(V, K)``
    float32 weights with ``K = max_influences``, each row summing to 1, unused slots joint
    0 with weight 0; and the JSON report of ``atlas-skin skin --report`` as a dict
    (decomposition, counts, timings, warnings and their topics, quality).

    Raises ``QualityGateError`` when ``fail_on`` rejects the result (its ``report`` is the
    report), ``ValueError`` for a wrong shape or dtype, a value that is not finite, an
    index out of range, an invalid skeleton (a cycle), or input the method refuses (the
    message of the command line, e.g. ``cannot skin the given arrays: ...``);
    ``FileNotFoundError`` for a missing ``config``.
    """

def load(
    path: StrPath,
    *,
    skeleton: Optional[StrPath] = None,
    group: Optional[str] = None,
    weights: Optional[StrPath] = None,
) -> Dict[str, Any]:
    """Reads a character file (glTF/glb/vrm, FBX, OBJ/OFF/PLY/STL/MEDIT with ``skeleton``).

    ``skeleton``: a skeleton file for a bare mesh (.tgf, .bvh, .mhskel, .json, RigNet's
    ``_rig.txt``); ``group``: only this OBJ group; ``weights``: reference weights for a
    mesh without them (.dmat, .mhw).

    Returns a dict:

    - ``path``: str; ``warnings``: list of str (what the reader noticed).
    - ``positions``: ``(V, 3)`` float32; ``triangles``: ``(F, 3)`` uint32.
    - ``names``: list of ``J`` str; ``parents``: ``(J,)`` int64, ``-1`` for roots;
      ``joint_positions``: ``(J, 3)`` float32; ``tails``: ``(J, 3)`` float32, NaN rows
      where the file gives no tail; ``inverse_bind``: ``(J, 4, 4)`` float32 (``M[row,
      column]``, acting on column vectors); ``end_joints``: list of int. Empty when the
      file has no skeleton.
    - ``indices``, ``weights``: the file's own (reference) weights as ``(V, K)`` uint32 and
      float32 arrays (``K``: the most influences of any vertex), or None.

    ``compute_weights(c["positions"], c["triangles"], c["joint_positions"], c["parents"],
    tails=c["tails"], inverse_bind=c["inverse_bind"], names=c["names"],
    end_joints=c["end_joints"])`` gives the weights of ``atlas-skin skin`` on the same
    file.

    Raises ``FileNotFoundError`` for a missing file, ``ValueError`` for any other problem
    (the message names the file).
    """

def demo() -> Dict[str, Any]:
    """The built-in demo character (a closed humanoid with hands and feet, no weights), as
    ``load`` returns a file."""

def deform(
    positions: FloatArray,
    indices: IntArray,
    weights: FloatArray,
    palette: FloatArray,
    method: str,
) -> npt.NDArray[np.float32]:
    """``deform_lbs`` (``method="lbs"``) or ``deform_dqs`` (``"dqs"``)."""

def skin_file(
    input: StrPath,
    output: StrPath,
    *,
    report: Optional[StrPath] = None,
    html: Optional[StrPath] = None,
    debug_glb: Optional[StrPath] = None,
    rig_info: Optional[StrPath] = None,
    skeleton: Optional[StrPath] = None,
    group: Optional[str] = None,
    weights: Optional[StrPath] = None,
    keep_rejected: bool = False,
    **options: Unpack[MethodOptions],
) -> Dict[str, Any]:
    """The job of ``atlas-skin skin INPUT -o OUTPUT``: reads the character, computes its
    weights and writes the skinned glb ``output`` (and, when given, the JSON ``report``,
    the ``html`` report, the ``debug_glb`` view and the ``rig_info`` text), each written to
    a temporary file and renamed, never over an input. ``skeleton``, ``group``,
    ``weights`` as ``load``; the method's options as ``compute_weights``.

    With ``fail_on``, a rejected character raises ``QualityGateError``: its outputs are
    not written but the ``report``, under its rejected name (``R.rejected.json``), or,
    with ``keep_rejected`` (``--keep-rejected``), all of them under their rejected names
    (``OUT.rejected.glb``, the exception's ``output``); an earlier run's outputs under
    either name are removed.

    Returns the report (a dict, as ``report`` holds it). Raises ``FileNotFoundError`` for a
    missing input, ``ValueError`` with the command line's message for anything else.
    """

def batch(
    inputs: Union[StrPath, Sequence[StrPath]],
    out_dir: StrPath,
    *,
    jobs: Optional[int] = None,
    resume: bool = False,
    report: bool = False,
    html: bool = False,
    log: Optional[StrPath] = None,
    progress: Optional[Callable[[Dict[str, Any]], object]] = None,
    keep_rejected: bool = False,
    **options: Unpack[MethodOptions],
) -> Dict[str, Any]:
    """The job of ``atlas-skin batch INPUT... -o OUT_DIR``: every character of ``inputs``
    (files; folders, searched with their subfolders for .glb, .gltf, .vrm and .fbx files;
    glob patterns such as ``"chars/*.fbx"``) skinned to ``OUT_DIR/<name>.glb`` (with
    ``<name>.json`` when ``report``, ``<name>.html`` when ``html``), ``jobs`` files at a
    time (default: the number of cores). ``resume`` skips the files whose outputs exist
    and are newer than the file and the ``config``. A failing file does not stop the
    others. Each finished file appends a record to the JSON-lines ``log`` (default
    ``OUT_DIR/atlas-skin-batch.jsonl``). The method's options as ``compute_weights``.

    ``progress`` is called on the calling thread with each record as its file finishes
    (for a progress bar); a worker that finishes a file waits while ``jobs`` records are
    not yet taken. An exception from it, or Ctrl-C (``KeyboardInterrupt``), stops the
    batch within a few files: the files running finish (their outputs complete), the
    others are not started and are logged as ``"cancelled"``, then the exception is
    raised. (A Python started with SIGINT ignored, as a background job of a
    non-interactive shell is, does not turn Ctrl-C into ``KeyboardInterrupt``: call
    ``signal.signal(signal.SIGINT, signal.default_int_handler)`` first.)

    With ``fail_on``, a file the gate rejects is recorded as ``"rejected"`` with its
    ``reasons``, its outputs written under their rejected names only with
    ``keep_rejected`` (the record's ``kept``), as ``skin_file`` writes them.

    Returns ``{"records": [...], "summary": {...}}``: one record per file, in the order
    of the inputs (``input``, ``output``, ``status``: ``"ok"``, ``"failed"``,
    ``"skipped"``, ``"cancelled"`` or ``"rejected"``, ``error``: the message ``skin`` would
    print or None, ``reasons``, ``kept``, ``seconds``, ``timings_ms``, ``counts``,
    ``warnings``), and the totals (``files``, ``ok``, ``failed``, ``skipped``,
    ``cancelled``, ``rejected``, ``seconds``, ``characters_per_second``, ``log``). A failed
    or rejected file is in the records, not raised. Raises ``ValueError`` when the batch cannot start
    (a pattern matching nothing, a folder without character files, two inputs with one
    name, an output over an input).
    """

def transfer(
    source_vertices: npt.ArrayLike,
    source_triangles: npt.ArrayLike,
    source_indices: npt.ArrayLike,
    source_weights: npt.ArrayLike,
    target_vertices: npt.ArrayLike,
    target_triangles: npt.ArrayLike,
    *,
    joint_count: Optional[int] = None,
    max_influences: int = 4,
    distance: Optional[float] = None,
    angle_degrees: Optional[float] = None,
    flipped_normals: Optional[bool] = None,
    smooth_iterations: Optional[int] = None,
    smooth_alpha: Optional[float] = None,
) -> Tuple[npt.NDArray[np.uint32], npt.NDArray[np.float32], Dict[str, Any]]:
    """Carries the source's weights onto the target (Abdrashitov et al. 2023: closest
    point matching within ``distance`` times the source's bounding-box diagonal (0.05) and
    ``angle_degrees`` between normals (30; flipped normals accepted unless
    ``flipped_normals=False``), the other vertices inpainted by the smoothest completion,
    ``smooth_iterations`` rounds (10) of strength ``smooth_alpha`` (0.2) near the seam).

    ``source_vertices`` ``(V, 3)``, ``source_triangles`` ``(F, 3)``, ``source_indices`` and
    ``source_weights`` ``(V, K)`` (as ``load`` returns them), ``target_vertices``
    ``(T, 3)`` in the source's rest space, ``target_triangles`` ``(G, 3)``;
    ``joint_count``: the skeleton's joints (default: the largest index + 1).

    Returns ``(T, max_influences)`` uint32 indices and float32 weights (the largest,
    summing to 1, padded with joint 0 and weight 0) and a dict: ``counts`` (matched,
    inpainted, nearest, ...), ``pieces`` (each connected piece of the target),
    ``distance`` (the matching distance in the source's units), ``vertex_sources`` (per
    target vertex: "matched", "inpainted" or "nearest"). Raises ``ValueError`` for bad
    arrays or settings, a source without weights, a target nowhere near the source or of
    another size.
    """

def transfer_file(
    source: StrPath,
    targets: Sequence[StrPath],
    output: StrPath,
    *,
    meshes: Optional[Sequence[str]] = None,
    report: Optional[StrPath] = None,
    html: Optional[StrPath] = None,
    skeleton: Optional[StrPath] = None,
    weights: Optional[StrPath] = None,
    max_influences: int = 4,
    distance: Optional[float] = None,
    angle_degrees: Optional[float] = None,
    flipped_normals: Optional[bool] = None,
    smooth_iterations: Optional[int] = None,
    smooth_alpha: Optional[float] = None,
) -> Dict[str, Any]:
    """The job of ``atlas-skin transfer SOURCE TARGET... -o OUTPUT`` (or, with ``meshes``
    and no targets, ``--meshes``): writes the skinned glb (and the JSON ``report`` and
    ``html`` report when given), each written to a temporary file and renamed, never over
    an input. Settings as ``transfer``. Returns the report. Raises ``FileNotFoundError``
    for a missing input, ``ValueError`` with the command line's message otherwise.
    """

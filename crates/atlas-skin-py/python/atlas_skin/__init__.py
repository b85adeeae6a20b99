"""atlas-skin: automatic character skinning.

Cuts a mesh into regions at its skeleton's joints, lets neighbouring regions overlap along
the surface and turns the overlaps into smooth skinning weights (Lu, Hétroy, Gérot,
Thibert, INRIA RR-6406, 2008, with the extensions of the atlas-skin project).

- ``compute_weights``: weights of numpy arrays (vertices, triangles, joints).
- ``load`` / ``demo``: a character file (or the built-in demo character) as numpy arrays.
- ``deform_lbs`` / ``deform_dqs``: pose vertices with linear blend or dual quaternion
  skinning.
- ``skin_file``: the job of ``atlas-skin skin`` (a character file to a skinned glb).
- ``batch``: the job of ``atlas-skin batch`` (many files, several at a time, a log).
- ``transfer``: a skinned mesh's weights carried onto other meshes (clothes, hair, props),
  on numpy arrays; ``transfer_file``: the job of ``atlas-skin transfer``.

Bad input raises ``ValueError`` (``FileNotFoundError`` for a missing file) with the
message the command line prints. With ``fail_on`` (the quality gate), a rejected character
raises ``QualityGateError`` (``batch`` records it as ``"rejected"``). The GIL is released
while the Rust code works.
"""

from typing import Any

import numpy as np
import numpy.typing as npt

from ._atlas_skin import (
    QualityGateError,
    __version__,
    batch,
    compute_weights,
    deform,
    demo,
    load,
    skin_file,
    transfer,
    transfer_file,
)


def deform_lbs(positions: Any, indices: Any, weights: Any, palette: Any) -> npt.NDArray[np.float32]:
    """Linear blend skinning: ``p'_v = sum_i w_vi * palette[j_vi] @ [p_v, 1]``.

    ``positions``: ``(V, 3)`` bind-space floats; ``indices``: ``(V, K)`` integer joint
    indices below ``J``; ``weights``: ``(V, K)`` floats, used as given (zero entries are
    skipped); ``palette``: ``(J, 4, 4)`` floats, each joint's skinning matrix (its posed
    world transform times its inverse bind matrix, ``M[row, column]`` acting on column
    vectors). Returns the ``(V, 3)`` float32 posed positions. Raises ``ValueError`` for a
    wrong shape, a value that is not finite or an index out of range.
    """
    return deform(positions, indices, weights, palette, "lbs")


def deform_dqs(positions: Any, indices: Any, weights: Any, palette: Any) -> npt.NDArray[np.float32]:
    """Dual quaternion skinning (Kavan et al. 2007), arguments as ``deform_lbs``; the
    palette's matrices must be rigid (rotation and translation). A vertex without
    influences goes to the origin."""
    return deform(positions, indices, weights, palette, "dqs")


__all__ = [
    "QualityGateError",
    "__version__",
    "batch",
    "compute_weights",
    "deform_dqs",
    "deform_lbs",
    "demo",
    "load",
    "skin_file",
    "transfer",
    "transfer_file",
]

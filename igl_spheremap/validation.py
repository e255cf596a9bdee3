"""Input validation: is (V, F) a closed, manifold, connected genus-0 triangle mesh?

(Minimal placeholder; the full check matrix is being written.)
"""

from dataclasses import dataclass, field

import igl
import numpy as np

from .errors import MeshError


@dataclass
class ValidatedMesh:
    """A mesh that passed :func:`validate_mesh`, ready to map.

    Attributes
    ----------
    V : (k, 3) float64 array
        Referenced vertices of the input, in input order.
    F : (m, 3) int64 array
        Faces re-indexed into ``V``, oriented outward.
    vertex_index : (k,) int64 array
        Row of the input ``V`` for each row of ``V``.
    unreferenced : (j,) int64 array
        Input rows used by no face (dropped).
    orientation_flipped : bool
        All faces were flipped because the input was oriented inward.
    notes : list of str
        Human-readable record of every automatic fix.
    """

    V: np.ndarray
    F: np.ndarray
    vertex_index: np.ndarray
    unreferenced: np.ndarray
    orientation_flipped: bool = False
    notes: list = field(default_factory=list)


def validate_mesh(V, F):
    """Check and prepare a mesh for mapping (see module docstring)."""
    V = np.ascontiguousarray(V, dtype=np.float64)
    F = np.ascontiguousarray(F, dtype=np.int64)
    if V.ndim != 2 or V.shape[1] != 3 or F.ndim != 2 or F.shape[1] != 3:
        raise MeshError("shape", 1, f"V must be (n, 3) and F (m, 3); got {V.shape}, {F.shape}")
    n = V.shape[0]
    vol = igl.volume(np.vstack([V, V.mean(0)]), np.hstack([F, np.full((F.shape[0], 1), n)]))
    flipped = bool(np.sum(vol) > 0)  # igl.volume's sign convention: negative = outward
    notes = []
    if flipped:
        F = F[:, [0, 2, 1]].copy()
        notes.append("faces were oriented inward; flipped all faces")
    return ValidatedMesh(V=V, F=F, vertex_index=np.arange(n), unreferenced=np.zeros(0, np.int64),
                         orientation_flipped=flipped, notes=notes)

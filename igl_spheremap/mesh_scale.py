"""Exact power-of-two scaling of mesh coordinates (see :class:`igl_spheremap.ValidatedMesh`)."""

import numpy as np


def power_of_two_scaled(V, used):
    """``V * 2**e`` (exact) with the referenced vertices' bounding-box diagonal in [1, 2).

    Two exact steps: first the largest coordinate into [0.5, 1) (so the diagonal
    can neither overflow nor underflow), then the diagonal into [1, 2).
    """
    W = V[used]
    largest = float(np.abs(W).max())
    if largest == 0.0:
        return V, 1.0  # every referenced vertex at the origin: zero-length edges, reported later
    e = -int(np.frexp(largest)[1])
    W = np.ldexp(W, e)
    diag = float(np.linalg.norm(W.max(axis=0) - W.min(axis=0)))
    if diag > 0.0:
        e += 1 - int(np.frexp(diag)[1])
    if e == 0:
        return V, 1.0
    return np.ldexp(V, e), float(np.ldexp(1.0, e))

"""Icospheres: the standard resampling templates of the unit sphere."""

import numbers

import igl
import numpy as np

MAX_LEVEL = 9
"""Largest accepted subdivision level: 2,621,442 vertices, 5,242,880 faces (~190 MB of arrays)."""


def icosphere(level):
    """Unit icosphere: the regular icosahedron subdivided ``level`` times.

    Starts from ``igl.icosahedron`` and applies libigl's 4-to-1 midpoint
    subdivision (``igl.upsample``, one step at a time), projecting the vertices
    back onto the unit sphere after every step, so each new vertex is the
    normalized midpoint of an edge of the previous level.  Level 7 has the
    163,842 vertices of FreeSurfer's ``fsaverage`` (``ico7``) sphere, level 5
    the 10,242 of ``fsaverage5``; vertex sets are nested (the first
    ``10 * 4**(level - 1) + 2`` rows are the vertices of level ``level - 1``,
    bit for bit),
    but the vertex order of FreeSurfer's files is not reproduced.

    Parameters
    ----------
    level : int
        Number of subdivision steps, ``0 <= level <= MAX_LEVEL`` (9).

    Returns
    -------
    V : (10 * 4**level + 2, 3) float64 array
        Unit vectors (norms 1 to rounding).
    F : (20 * 4**level, 3) int64 array
        Triangles, oriented outward (counter-clockwise seen from outside), so
        every face has a positive signed volume ``det[V_i, V_j, V_k]``.

    Raises
    ------
    TypeError
        If ``level`` is not an integer (``bool`` is refused too).
    ValueError
        If ``level`` is negative or above :data:`MAX_LEVEL`.

    Notes
    -----
    Source: the geodesic icosahedral grid (Baumgardner & Frederickson, SIAM J.
    Numer. Anal. 1985) used for cortical surface templates (Fischl, Sereno,
    Tootell, Dale, Hum. Brain Mapp. 1999).
    """
    if isinstance(level, bool) or not isinstance(level, numbers.Integral):
        raise TypeError(f"icosphere level must be an integer, got {type(level).__name__} {level!r}")
    level = int(level)
    if not 0 <= level <= MAX_LEVEL:
        size = f" ({10 * 4 ** level + 2} vertices)" if level > MAX_LEVEL else ""
        raise ValueError(f"icosphere level must be between 0 and {MAX_LEVEL}, got {level}{size}")
    V, F = igl.icosahedron()
    V = V / np.linalg.norm(V, axis=1, keepdims=True)
    for _ in range(level):
        n = V.shape[0]
        V, F = igl.upsample(V, F)  # keeps the old vertices on top, bit for bit
        V[n:] /= np.linalg.norm(V[n:], axis=1, keepdims=True)
    return np.ascontiguousarray(V, dtype=np.float64), np.ascontiguousarray(F, dtype=np.int64)

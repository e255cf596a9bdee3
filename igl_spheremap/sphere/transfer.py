"""Sparse barycentric interpolation matrix from located points."""

import numpy as np
import scipy.sparse

from ..errors import plural

BARY_TOL = 1e-9
"""Largest accepted deviation of a row sum of ``bary`` from 1 (and of an entry below 0)."""


def barycentric_matrix(face, bary, F, n=None):
    """Sparse matrix carrying per-vertex data of a mesh to points given in barycentric form.

    Row ``p`` holds ``bary[p]`` in the columns ``F[face[p]]``, so for per-vertex
    data ``X`` of the source mesh, ``(P @ X)[p] = sum_c bary[p, c] X[F[face[p], c]]``,
    the linear (barycentric) interpolation that ``igl.barycentric_interpolation``
    computes, as a reusable operator: build it once (e.g. from
    :func:`igl_spheremap.sphere.locate.locate_on_sphere`) and apply it to any
    number of data columns, or transpose it to carry data back.

    Parameters
    ----------
    face : (k,) int array
        Row of ``F`` of each point.
    bary : (k, 3) float array
        Barycentric coordinates of each point in ``F[face]``: non-negative (down
        to ``-BARY_TOL``, then clipped), rows summing to 1 within ``BARY_TOL``;
        rows are renormalized to sum to 1 to rounding.
    F : (m, 3) int array
        Triangles of the source mesh.
    n : int, optional
        Number of source vertices (columns); default ``F.max() + 1``.  Pass it
        when the source has vertices no face uses.

    Returns
    -------
    P : (k, n) scipy.sparse.csr_matrix of float64
        Non-negative, at most 3 stored entries per row (zero weights are not
        stored), each row summing to 1.

    Raises
    ------
    ValueError
        If a shape is wrong, ``face`` indexes outside ``F``, ``F`` indexes
        outside ``n`` vertices, or ``bary`` holds non-finite, negative or
        non-normalized rows (the message gives the count).
    """
    face = np.asarray(face)
    bary = np.asarray(bary, dtype=np.float64)
    F = np.asarray(F)
    if F.ndim != 2 or F.shape[1] != 3 or not np.issubdtype(F.dtype, np.integer):
        raise ValueError(f"F must be an (m, 3) integer array, got shape {F.shape}, dtype {F.dtype}")
    if face.ndim != 1 or not (np.issubdtype(face.dtype, np.integer) or face.size == 0):
        raise ValueError(f"face must be a (k,) integer array, got shape {face.shape}, dtype {face.dtype}")
    k = face.shape[0]
    if bary.shape != (k, 3):
        raise ValueError(f"bary must have shape ({k}, 3) to match face, got {bary.shape}")
    if n is None:
        n = int(F.max()) + 1 if F.size else 0
    bad = np.count_nonzero((face < 0) | (face >= F.shape[0]))
    if bad:
        raise ValueError(f"face has {plural(bad, 'entry', 'entries')} outside [0, {F.shape[0]})")
    bad = np.count_nonzero((F < 0) | (F >= n))
    if bad:
        raise ValueError(f"F has {plural(bad, 'vertex index', 'vertex indices')} outside [0, {n})")
    bad = np.count_nonzero(~np.isfinite(bary).all(axis=1))
    if bad:
        raise ValueError(f"bary has {plural(bad, 'row')} with non-finite values")
    bad = np.count_nonzero((bary < -BARY_TOL).any(axis=1))
    if bad:
        raise ValueError(f"bary has {plural(bad, 'row')} with negative coordinates (below "
                         f"-{BARY_TOL:g})")
    bad = np.count_nonzero(np.abs(bary.sum(axis=1) - 1.0) > BARY_TOL)
    if bad:
        raise ValueError(f"bary has {plural(bad, 'row that does', 'rows that do')} not sum to 1 "
                         f"(within {BARY_TOL:g})")
    W = np.maximum(bary, 0.0)
    W /= W.sum(axis=1, keepdims=True)
    rows = np.repeat(np.arange(k), 3)
    cols = F[face.astype(np.int64)].ravel()
    P = scipy.sparse.csr_matrix((W.ravel(), (rows, cols)), shape=(k, n))
    P.eliminate_zeros()
    P.sort_indices()
    return P

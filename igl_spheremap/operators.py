"""Discrete operators of the harmonic energy (paper Eq. 13) built from libigl."""

import igl
import numpy as np

from .errors import MeshError

LAPLACIANS = ("intrinsic_delaunay", "cotan")

SLIVER_RTOL = 1e-5
"""A face is a sliver when its smallest height is below this times its longest edge.

Below it libigl's intrinsic Delaunay flips can run away (see :func:`height_ratios`).
Measured by ``benchmarks/sliver_statistic.py``: the 14 shared real meshes have
ratios >= 6.6e-4 (pycortex pial; next 6.1e-3), the split icospheres of issue #15
on which the flips diverged <= 6.9e-7."""


def laplacian(V, F, kind="intrinsic_delaunay"):
    """Cotangent Laplacian of a triangle mesh, as libigl builds it.

    Parameters
    ----------
    V : (n, 3) float64 array
        Vertex positions.
    F : (m, 3) int64 array
        Triangle indices into ``V``.
    kind : {"intrinsic_delaunay", "cotan"}
        ``"cotan"`` is ``igl.cotmatrix``, the discretisation of paper Eq. 13;
        it has negative edge weights wherever an edge is not Delaunay.
        ``"intrinsic_delaunay"`` is ``igl.intrinsic_delaunay_cotmatrix``, the
        same operator on the intrinsic Delaunay retriangulation of the same
        surface (all edge weights >= 0).

    Returns
    -------
    L : (n, n) scipy.sparse.csr_matrix of float64
        Symmetric negative semidefinite; rows sum to zero.  Scale invariant.

    Raises
    ------
    ValueError
        If ``kind`` is not one of :data:`LAPLACIANS`.
    MeshError
        ``problem="slivers"``, ``count`` = faces: ``kind="intrinsic_delaunay"`` on
        a mesh with faces whose smallest height is below :data:`SLIVER_RTOL` times
        their longest edge (:func:`height_ratios`).  libigl's edge flips can loop
        without end on such meshes; the check refuses them before libigl runs.
    """
    if kind == "cotan":
        L = igl.cotmatrix(V, F)
    elif kind == "intrinsic_delaunay":
        _refuse_slivers(V, F)
        L = igl.intrinsic_delaunay_cotmatrix(V, F)[0]
    else:
        raise ValueError(f"unknown Laplacian {kind!r}; expected one of {LAPLACIANS}")
    return L.tocsr()


def height_ratios(V, F):
    """Smallest height over longest edge of each face, ``2 A / l_max**2``.

    Scale invariant, in ``[0, sqrt(3) / 2]`` (equilateral).  It bounds both ways
    a face can break ``igl.intrinsic_delaunay_cotmatrix``: the ratio ``rho`` of
    shortest to longest edge is ``>=`` it, and the relative slack of the
    triangle inequality, ``min(l_i + l_j - l_k) / l_max``, is ``>= ratio**2``.
    A flip computes the new edge length by the law of cosines from the two long
    sides, with relative error ``~ eps / rho**2``; once that exceeds the slack of
    a new triangle (needles, ``rho`` <~ 1e-6), or the input's own slack is at
    rounding level (caps, ratio <~ 1e-8), ``tan_half_angle`` gives NaN, the NaN
    edge fails the Delaunay test forever, and libigl's flip stack grows by three
    entries per flip until memory runs out (issue #15).

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int64 array

    Returns
    -------
    (m,) float64 array
        Per face; 0 for a face of zero area.  Areas from ``igl.doublearea`` and
        lengths from ``igl.edge_lengths``, on ``V`` centred on its bounding box
        (less rounding for meshes far from the origin).
    """
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    X = V - 0.5 * (V.min(axis=0) + V.max(axis=0))
    l = igl.edge_lengths(X, F)
    lmax = np.maximum(np.maximum(l[:, 0], l[:, 1]), l[:, 2])  # 2x faster than l.max(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = igl.doublearea(X, F) / (lmax * lmax)
    return np.nan_to_num(ratio, nan=0.0)


def _refuse_slivers(V, F):
    ratio = height_ratios(V, F)
    bad = ratio < SLIVER_RTOL
    if bad.any():
        k, f = int(np.count_nonzero(bad)), int(np.argmin(ratio))
        raise MeshError("slivers", k, (
            f"invalid mesh (slivers): {k} face{'s' if k != 1 else ''} whose smallest height is "
            f"below {SLIVER_RTOL:g} x its longest edge (smallest: {ratio[f]:.2g}, face {f}); "
            "there the edge flips of libigl's intrinsic Delaunay Laplacian can loop until "
            "memory runs out (rounding breaks the triangle inequality of the intrinsic edge "
            "lengths). Collapse the short edges (igl.decimate collapses the shortest first) or "
            "remesh, or use laplacian_kind=\"cotan\"."))


def vertex_areas(V, F):
    """Lumped barycentric vertex areas ``A_i`` of paper Eq. 13.

    ``A_i`` is one third of the total area of the faces around vertex ``i``
    (face areas from ``igl.doublearea``, summed per vertex with
    ``numpy.bincount``); it is the diagonal of
    ``igl.massmatrix(V, F, MASSMATRIX_TYPE_BARYCENTRIC)`` (up to rounding)
    without assembling the sparse matrix: at 1M vertices 0.1 s and 15 MB of
    temporaries instead of 0.6 s and 360 MB.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int64 array

    Returns
    -------
    A : (n,) float64 array
        Vertex areas in the squared units of ``V``; they sum to the surface area.
        Vertices used by no face get 0.
    """
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F)
    third = igl.doublearea(V, F) / 6.0
    n = V.shape[0]
    A = np.bincount(F[:, 0], weights=third, minlength=n)
    A += np.bincount(F[:, 1], weights=third, minlength=n)
    A += np.bincount(F[:, 2], weights=third, minlength=n)
    return A


def count_negative_weights(L, rtol=1e-12):
    """Number of edges whose cotangent weight is negative (beyond rounding).

    Parameters
    ----------
    L : (n, n) sparse matrix
        A Laplacian from :func:`laplacian`.
    rtol : float
        Weights above ``-rtol * max |w|`` count as non-negative (rounding).

    Returns
    -------
    int
        Number of unordered vertex pairs ``(i, j)``, ``i < j``, with ``L[i, j] < 0``
        (``L[i, j]`` is the weight ``w_ij`` of edge ``ij``).
    """
    T = L.tocoo()
    upper = T.row < T.col
    w = T.data[upper]
    return int(np.count_nonzero(w < -rtol * np.abs(w).max()))

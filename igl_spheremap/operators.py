"""Discrete operators of the harmonic energy (paper Eq. 13) built from libigl."""

import igl
import numpy as np

from .bounded_intrinsic_delaunay import bounded_intrinsic_delaunay_cotmatrix

LAPLACIANS = ("intrinsic_delaunay", "cotan")

#: Area of the unit sphere.  Meshes are scaled to it before Algorithm 1 (so one
#: tolerance means the same on every mesh), and a conformal bijection onto the
#: unit sphere has harmonic energy ``SPHERE_AREA``.
SPHERE_AREA = 4.0 * np.pi

NEEDLE_RTOL = 1e-2
"""Shortest / longest edge of a face below which libigl's intrinsic Delaunay flips are not used."""
CAP_RTOL = 1e-10
"""Relative triangle-inequality slack of a face below which they are not used either."""


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
        surface (all edge weights >= 0).  On meshes with slivers
        (:func:`sliver_statistics` below :data:`NEEDLE_RTOL` or :data:`CAP_RTOL`),
        where libigl's flips can loop until memory runs out (issue #15), the same
        algorithm with bounded work:
        :func:`~igl_spheremap.bounded_intrinsic_delaunay.bounded_intrinsic_delaunay_cotmatrix`
        (identical wherever libigl ends; a flip that would make a degenerate
        triangle is skipped, so a few weights may stay negative).

    Returns
    -------
    L : (n, n) scipy.sparse.csr_matrix of float64
        Symmetric negative semidefinite; rows sum to zero.  Scale invariant.

    Raises
    ------
    ValueError
        If ``kind`` is not one of :data:`LAPLACIANS`.
    MeshError
        ``problem="slivers"`` (intrinsic Delaunay only): faces whose edge
        lengths are degenerate at rounding level, or the flip limit reached.
    """
    if kind == "cotan":
        L = igl.cotmatrix(V, F)
    elif kind == "intrinsic_delaunay":
        edge_ratio, slack = sliver_statistics(V, F)
        if edge_ratio.min() < NEEDLE_RTOL or slack.min() < CAP_RTOL:
            L = bounded_intrinsic_delaunay_cotmatrix(V, F)[0]
        else:
            L = igl.intrinsic_delaunay_cotmatrix(V, F)[0]
    else:
        raise ValueError(f"unknown Laplacian {kind!r}; expected one of {LAPLACIANS}")
    return L.tocsr()


def sliver_statistics(V, F):
    """Per face: shortest / longest edge, and the relative slack of the triangle inequality.

    From the edge lengths ``igl.intrinsic_delaunay_cotmatrix`` starts from
    (``igl.edge_lengths(V, F)``).  A flip computes the new edge's length by the
    law of cosines from the quad's long sides, with relative error
    ``~ eps / edge_ratio**2`` where the new edge is short; libigl's flips break
    down (NaN lengths, endless flips) once that exceeds the slack of a new
    triangle (needles: small edge ratio), or when an input triangle's own slack
    is at rounding level (caps).  Measured (``benchmarks/sliver_statistic.py``,
    ``scratch/``): the 14 shared meshes have edge ratios >= 0.033 and slack
    >= 8.8e-7; libigl diverged on icospheres with needles at edge ratios up to
    2.6e-5 (20k faces; the limit grows with the number of needles and with
    refinement) and with caps at slack <= 2e-16.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int64 array

    Returns
    -------
    edge_ratio : (m,) float64 array
        ``min(l) / max(l)`` per face, in ``[0, 1]``.
    slack : (m,) float64 array
        ``min_k (l_i + l_j - l_k) / max(l)`` per face, in ``[0, 1]``; <= 0 when
        the lengths violate or meet the triangle inequality.
    """
    l = igl.edge_lengths(np.asarray(V, dtype=np.float64), np.asarray(F, dtype=np.int64))
    lo = np.minimum(np.minimum(l[:, 0], l[:, 1]), l[:, 2])
    hi = np.maximum(np.maximum(l[:, 0], l[:, 1]), l[:, 2])
    with np.errstate(divide="ignore", invalid="ignore"):
        return lo / hi, (l[:, 0] + l[:, 1] + l[:, 2] - 2 * hi) / hi


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


def to_sphere_area(a):
    """Areas ``a`` scaled to total :data:`SPHERE_AREA` (``4 pi``), as a new array.

    Parameters
    ----------
    a : (k,) float64 array
        Non-negative areas (vertex or face areas) with a positive sum.

    Returns
    -------
    (k,) float64 array
    """
    return a * (SPHERE_AREA / a.sum())


def dirichlet_energy(L, U, LU=None):
    """Discrete harmonic (Dirichlet) energy ``E(U) = -1/2 tr(U^T L U)`` (paper Eqs. 6, 13).

    ``= 1/2 sum_{edges ij} w_ij |U_i - U_j|^2`` with the edge weights ``w_ij`` of
    ``L``.  It does not depend on the scale of the mesh; for a conformal
    bijection onto the unit sphere it approaches :data:`SPHERE_AREA`.

    Parameters
    ----------
    L : (n, n) sparse matrix
        Negative semidefinite Laplacian.
    U : (n, 3) float64 array
    LU : (n, 3) float64 array, optional
        ``L @ U`` if already computed.

    Returns
    -------
    float
    """
    if LU is None:
        LU = L @ U
    return -0.5 * float(np.vdot(U, LU))


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

"""Discrete operators of a triangle mesh from libigl: the Laplacian and vertex areas of the
harmonic energy (paper Eq. 13), signed volumes, and mean value weights."""

import igl
import numpy as np
import scipy.sparse as sp

from .intrinsic_delaunay import intrinsic_delaunay_cotmatrix

LAPLACIANS = ("intrinsic_delaunay", "cotan")

#: Area of the unit sphere.  Meshes are scaled to it before Algorithm 1 (so one
#: tolerance means the same on every mesh), and a conformal bijection onto the
#: unit sphere has harmonic energy ``SPHERE_AREA``.
SPHERE_AREA = 4.0 * np.pi

CHUNK_FACES = 1 << 14
"""Faces per block in :func:`signed_volumes` (temporaries stay in cache)."""


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
        ``"intrinsic_delaunay"`` is the same operator on the intrinsic Delaunay
        retriangulation of the same surface (all edge weights >= 0):
        :func:`igl_spheremap.mesh.intrinsic_delaunay.intrinsic_delaunay_cotmatrix`
        (libigl's, or the same flips with bounded work on meshes with slivers).

    Returns
    -------
    L : (n, n) scipy.sparse.csr_matrix of float64
        Symmetric negative semidefinite; rows sum to zero.  Scale invariant.

    Raises
    ------
    ValueError
        If ``kind`` is not one of :data:`LAPLACIANS`.
    MeshError
        ``problem="slivers"`` (intrinsic Delaunay only): the flip limit reached
        (faces of zero area get the mollified metric,
        :func:`igl_spheremap.mesh.intrinsic_delaunay.intrinsic_delaunay_cotmatrix`).
    """
    if kind == "cotan":
        L = igl.cotmatrix(V, F)
    elif kind == "intrinsic_delaunay":
        L = intrinsic_delaunay_cotmatrix(V, F)
    else:
        raise ValueError(f"unknown Laplacian {kind!r}; expected one of {LAPLACIANS}")
    return L.tocsr()


def vertex_areas(V, F):
    """Lumped barycentric vertex areas ``A_i`` of paper Eq. 13.

    ``A_i`` is one third of the total area of the faces around vertex ``i``
    (face areas from ``igl.doublearea``, summed per vertex with
    ``numpy.bincount``); it is the diagonal of
    ``igl.massmatrix(V, F, MASSMATRIX_TYPE_BARYCENTRIC)`` (up to rounding)
    without assembling the sparse matrix (``docs/decisions.md``).

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


def signed_volumes(F, U):
    """Six times the signed volume of the tetrahedron (0, U_i, U_j, U_k) per face.

    Computed as ``((U_j - U_i) x (U_k - U_i)) . (U_i + U_j + U_k) / 3`` from edge
    differences, which
    equals ``det[U_i, U_j, U_k]`` in exact arithmetic but keeps a correct sign on
    the tiny, crowded image triangles of thin features (the triple product of
    the raw unit vectors cancels catastrophically there).

    The coordinates are gathered and combined one component at a time in
    blocks of :data:`CHUNK_FACES` faces, so the temporaries stay small (a
    transposed copy of ``U``, or of the faces' corners alone where ``3 m < n``,
    and ~2 MB of block buffers whatever ``m``) and in cache
    (``docs/decisions.md``).  This runs in every line-search trial of the fold
    barrier and after each halving of a blend.

    Parameters
    ----------
    F : (m, 3) int array
    U : (n, 3) float64 array
        Points on (or near) the unit sphere.

    Returns
    -------
    s : (m,) float64 array
        Positive for a face whose image keeps the orientation of an outward
        oriented input; negative for an inverted (folded) face.
    """
    F, U = np.asarray(F), np.asarray(U, dtype=np.float64)
    m, n = F.shape[0], U.shape[0]
    if m and not -n <= F.min() <= F.max() < n:  # checked once: the blocks take with mode="wrap"
        bad = F.max() if F.max() >= n else F.min()
        raise IndexError(f"index {bad} is out of bounds for axis 0 with size {n}")
    if 3 * m < n:  # a few faces of a large map (the fold tests of a blend): their corners only
        U, F = U[F.ravel()], np.arange(3 * m).reshape(m, 3)
    X, Y, Z = np.array(U.T, order="C")
    s = np.empty(m)
    buf = np.empty((13, min(CHUNK_FACES, m)))
    for a in range(0, m, CHUNK_FACES):
        b = min(a + CHUNK_FACES, m)
        xi, xj, xk, yi, yj, yk, zi, zj, zk, sx, sy, sz, t = buf[:, : b - a]
        i, j, k = np.array(F[a:b].T, dtype=np.intp)  # contiguous index rows
        for C, ci, cj, ck, sc in ((X, xi, xj, xk, sx), (Y, yi, yj, yk, sy), (Z, zi, zj, zk, sz)):
            C.take(i, out=ci, mode="wrap")
            C.take(j, out=cj, mode="wrap")
            C.take(k, out=ck, mode="wrap")
            np.add(ci, cj, out=sc)
            sc += ck  # U_i + U_j + U_k
            cj -= ci  # U_j - U_i
            ck -= ci  # U_k - U_i
        # ((U_j - U_i) x (U_k - U_i)) . (U_i + U_j + U_k), one component at a time
        for c, p, q, r, u, v in ((xi, yj, zk, zj, yk, sx), (yi, zj, xk, xj, zk, sy),
                                 (zi, xj, yk, yj, xk, sz)):
            np.multiply(p, q, out=c)
            np.multiply(r, u, out=t)
            c -= t
            c *= v
        out = s[a:b]
        np.add(xi, yi, out=out)
        out += zi
    s /= 3.0
    return s


def mean_value_weights(V, F, E):
    """Mean value weights ``w_ij`` and ``w_ji`` of the edges ``E`` of a triangle mesh.

    ``w_ij = (tan(a / 2) + tan(b / 2)) / |x_i - x_j|`` with ``a`` and ``b`` the
    angles at ``i`` of the faces on either side of edge ``ij`` (one face on a
    boundary edge).  Positive for any mesh without degenerate angles, so a
    Tutte embedding with these weights and a convex boundary is fold-free (M. S.
    Floater, "Mean value coordinates", CAGD 20(1), 2003, Eq. 3.1; Tutte's theorem
    in Floater's form, "One-to-one piecewise linear mappings over
    triangulations", Math. Comp. 72, 2003).  Not symmetric.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int64 array
    E : (e, 2) int array
        Edges ``(i, j)`` of ``F``.

    Returns
    -------
    (e, 2) float64 array
        Column 0: ``w_ij`` (row ``i`` of a Tutte system), column 1: ``w_ji``.
    """
    ang = igl.internal_angles(V, F)  # (m, 3): the angle at corner c
    n = V.shape[0]
    rows, cols, vals = [], [], []
    for c in range(3):
        i, j, k = F[:, c], F[:, (c + 1) % 3], F[:, (c + 2) % 3]
        t = np.tan(ang[:, c] / 2.0)
        rows += [i, i]  # the angle at i lies between its edges ij and ik
        cols += [j, k]
        vals += [t, t]
    T = sp.coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(n, n)).tocsr()
    length = np.linalg.norm(V[E[:, 0]] - V[E[:, 1]], axis=1)
    wij = np.asarray(T[E[:, 0], E[:, 1]]).ravel() / length
    wji = np.asarray(T[E[:, 1], E[:, 0]]).ravel() / length
    return np.column_stack([wij, wji])

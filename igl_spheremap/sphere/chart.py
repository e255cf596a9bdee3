"""Local re-embedding of part of a spherical map: the gnomonic chart and the Tutte patch.

The gnomonic (central) projection onto the plane tangent at a unit vector ``c``
maps great circles to lines and keeps the orientation of every triangle whose
corners lie in the open hemisphere around ``c``: a spherical patch that fits in
the chart can be re-embedded in the plane and brought back without changing
which faces are folded.  Inside the chart a disk patch is re-embedded by Tutte's
barycentric method: every interior vertex at a positively weighted average of
its neighbours, the boundary held; with a convex boundary polygon the embedding
is fold-free (W. T. Tutte, "How to draw a graph", Proc. London Math. Soc. 1963;
M. S. Floater, "One-to-one piecewise linear mappings over triangulations", Math.
Comp. 72, 2003).  Used by the untangling of folds
(:func:`igl_spheremap.folding.untangle.untangle_folds`) and by the inflation of
crowded clusters (:mod:`igl_spheremap.precision.inflation`).
"""

import igl
import numpy as np
import scipy.sparse as sp

#: Points fit a chart when they lie above this height (cosine of their angle to the
#: center, 88.9 degrees): every orientation is kept for any positive height, and
#: chart coordinates stay below ``1 / MIN_HEIGHT`` = 50, far from rounding trouble.
MIN_HEIGHT = 0.02


def tangent_basis(c):
    """Orthonormal ``e1, e2`` ((3,) float64 each) of the plane tangent at unit ``c``, ``e1 x e2 = c``."""
    e1 = np.cross(c, [1.0, 0.0, 0.0] if abs(c[0]) < 0.9 else [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(c, e1)


class GnomonicChart:
    """The gnomonic projection onto the plane tangent to the unit sphere at ``c``.

    Parameters
    ----------
    c : (3,) float64 array
        Unit vector, the center of the chart.

    Attributes
    ----------
    c, e1, e2 : (3,) float64 arrays
        Center and an orthonormal basis of the tangent plane, ``e1 x e2 = c``.
    """

    def __init__(self, c):
        self.c = c
        self.e1, self.e2 = tangent_basis(c)

    @classmethod
    def around(cls, P):
        """The chart centered at the normalized sum of the unit vectors ``P`` (k, 3)."""
        c = P.sum(axis=0)
        c /= np.linalg.norm(c)
        return cls(c)

    def heights(self, P):
        """``P @ c``: the cosine of each point's angle to the center ((k,) float64)."""
        return P @ self.c

    def fits(self, P):
        """Whether every point of ``P`` (k, 3) lies above :data:`MIN_HEIGHT` in the chart."""
        return bool(self.heights(P).min() > MIN_HEIGHT)

    def to_plane(self, P):
        """Chart coordinates ((k, 2) float64) of unit vectors ``P`` (k, 3) in the hemisphere."""
        Q = P / self.heights(P)[:, None]
        return np.column_stack([Q @ self.e1, Q @ self.e2])

    def to_sphere(self, X):
        """Unit vectors ((k, 3) float64) of chart points ``X`` (k, 2)."""
        Z = self.c + np.outer(X[:, 0], self.e1) + np.outer(X[:, 1], self.e2)
        return Z / np.linalg.norm(Z, axis=1, keepdims=True)


def disk_patch(F, faces, inside):
    """The faces ``faces`` of ``F`` as a disk with local indices, or None.

    Parameters
    ----------
    F : (m, 3) int64 array
    faces : (f,) int array
        Rows of ``F`` forming the patch.
    inside : (n,) bool array
        Vertices that must be interior (not on the patch's boundary).

    Returns
    -------
    tuple or None
        ``(verts, Fl, boundary)``: the patch's vertices (k,) int64 (rows of the
        map), its faces in local indices (f, 3) and its boundary mask (k,) bool;
        None when the patch is not a disk with one boundary loop, or a vertex of
        ``inside`` lies on that loop.
    """
    Fp = F[faces]
    verts = np.unique(Fp)
    local = -np.ones(inside.shape[0], dtype=np.int64)
    local[verts] = np.arange(verts.size)
    Fl = local[Fp]
    if verts.size - igl.edges(Fl).shape[0] + Fl.shape[0] != 1:
        return None  # Euler characteristic of a disk is 1
    loops = igl.boundary_loop_all(Fl)
    if len(loops) != 1:
        return None
    boundary = np.zeros(verts.size, dtype=bool)
    boundary[np.asarray(loops[0], dtype=np.int64)] = True
    if np.any(boundary & inside[verts]):
        return None
    return verts, Fl, boundary


class TutteSystem:
    """The Tutte system of a planar disk patch, set up once for solves with changing weights.

    ``sum_j w_ij (Y_i - Y_j) = 0`` at every free vertex: the free block of the weighted
    Laplacian ``L_w = diag(A 1) - A`` (``A_ij = w_ij`` on the edges) is solved against
    the fixed vertices' pull.  The sparsity patterns and where each weight goes in them
    are found once; a solve only fills in the values, so that the reweighting loop of
    :func:`reweighted_tutte` does not build the matrices again at every step.  The matrices
    are those :func:`scipy.sparse` builds from the edge list, entry by entry (the same
    sums, the same order), so a solve gives the same result to the bit.

    With ``repeated=True`` (many solves, as in :func:`reweighted_tutte`) the free vertices
    are numbered once in a fill-reducing order (SuperLU's minimum degree ordering of the
    block's pattern, which does not depend on the weights), and each solve factorizes the
    block in that order without pivoting: the block is a nonsingular M-matrix (positive
    weights, diagonally dominant by rows, every part of the interior held by the
    boundary), whose Gaussian elimination needs no pivots and keeps every Schur complement
    an M-matrix (Fiedler, Pták 1962).  The solution is the same to rounding, not to the
    bit, a solve costs less than :func:`scipy.sparse.linalg.spsolve`'s (which orders the
    columns again every time), and with weights spanning many orders of magnitude the
    embedding stays fold-free where partial pivoting's rounding folds faces
    (``docs/decisions.md``).

    Parameters
    ----------
    F : (f, 3) int64 array
        The patch's faces (local indices).
    fixed : (k,) bool array
        Vertices held where they are (the boundary).
    repeated : bool
        Number the free vertices for many solves (above).
    """

    def __init__(self, F, fixed, repeated=False):
        n = fixed.size
        self.E = igl.edges(F)
        e = self.E.shape[0]
        tail, head = np.r_[self.E[:, 0], self.E[:, 1]], np.r_[self.E[:, 1], self.E[:, 0]]
        self.A = _slots(tail, head, (n, n), sp.csr_matrix)  # A.data: slots of the 2e weights
        free = ~fixed
        self.free, self.fixed, self.order = free, fixed, None
        self._number(tail, head, np.cumsum(free) - 1)
        if repeated and free.any():
            K = _filled(self.block, np.r_[-np.ones(2 * e), self._row_sums(np.ones(2 * e))[free]])
            self.order = _minimum_degree_order(K)
            local = np.full(n, -1)
            local[np.flatnonzero(free)[self.order]] = np.arange(self.order.size)
            self._number(tail, head, local)

    def _number(self, tail, head, local):
        """The block and pull patterns with the free vertices numbered ``local``."""
        free, fixed, e = self.free, self.fixed, self.E.shape[0]
        inner = free[tail] & free[head]
        # the free block of L_w: -w on the inner edges (slots < 2e), A 1 on the diagonal
        self.block = _slots(np.r_[local[tail[inner]], local[free]],
                            np.r_[local[head[inner]], local[free]], (free.sum(),) * 2,
                            sp.csc_matrix, np.r_[np.flatnonzero(inner), 2 * e + np.arange(free.sum())])
        across = free[tail] & fixed[head]
        self.pull = _slots(local[tail[across]], (np.cumsum(fixed) - 1)[head[across]],
                           (free.sum(), fixed.sum()), sp.csr_matrix, np.flatnonzero(across))

    def solve(self, X, W=None):
        """The embedding with edge weights ``W`` ((e, 2): ``w_ij, w_ji`` of the edges
        ``igl.edges(F)``; default 1) and the fixed vertices at ``X`` ((k, 2)); as
        :func:`tutte_embedding`."""
        from scipy.sparse.linalg import splu, spsolve

        w = np.ones(2 * self.E.shape[0]) if W is None else np.r_[W[:, 0], W[:, 1]]
        K = _filled(self.block, np.r_[-w, self._row_sums(w[self.A.data])[self.free]])
        b = _filled(self.pull, w) @ X[self.fixed]
        Y = X.copy()
        if self.order is None:
            Y[self.free] = spsolve(K, b)
        else:  # the free vertices in self.order
            Y[np.flatnonzero(self.free)[self.order]] = splu(
                K, permc_spec="NATURAL", diag_pivot_thresh=0.0, relax=1, panel_size=1,
                options=dict(SymmetricMode=True)).solve(b)
        return Y

    def _row_sums(self, data):
        """``A 1`` from ``A``'s entries, summed as scipy sums a CSR matrix's rows (0 on a row
        without entries, such as a puncture in no face)."""
        rows = np.flatnonzero(np.diff(self.A.indptr))
        out = np.zeros(self.A.shape[0])
        out[rows] = np.add.reduceat(data, self.A.indptr[rows])
        return out


def _minimum_degree_order(K):
    """SuperLU's minimum degree ordering of ``K + K^T`` (a permutation of ``K``'s rows, (k,)
    int64): ``K[order][:, order]`` factorizes with little fill."""
    from scipy.sparse.linalg import splu

    perm_c = splu(K, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                  options=dict(SymmetricMode=True)).perm_c
    return np.argsort(perm_c)


def _slots(rows, cols, shape, kind, ids=None):
    """A sparse matrix of ``kind`` whose entry ``(rows[k], cols[k])`` holds ``ids[k]`` (default
    ``k``), in the canonical order scipy gives a matrix built from these triplets."""
    ids = np.arange(rows.size) if ids is None else ids
    M = kind((ids + 1.0, (rows, cols)), shape=shape)  # no duplicate entries: edges are unique
    M.sort_indices()
    M.data = M.data.astype(np.int64) - 1
    return M


def _filled(pattern, values):
    """``pattern`` (from :func:`_slots`) with each entry's slot replaced by its value."""
    M = pattern.copy()
    M.data = values[pattern.data]
    return M


def tutte_embedding(X, F, fixed, W=None):
    """Tutte embedding of a planar disk: ``sum_j w_ij (Y_i - Y_j) = 0`` at every free vertex.

    Parameters
    ----------
    X : (k, 2) float64 array
        Chart positions; only the rows of ``fixed`` vertices are used.
    F : (f, 3) int64 array
        The patch's faces (local indices).
    fixed : (k,) bool array
        Vertices held at ``X`` (the boundary).
    W : (e, 2) float64 array, optional
        Positive weights ``w_ij, w_ji`` of the edges ``igl.edges(F)`` (e.g.
        :func:`igl_spheremap.mesh.operators.mean_value_weights`); default 1
        (Tutte's uniform weights).

    Returns
    -------
    (k, 2) float64 array
        ``X`` on the fixed vertices, the solution elsewhere.
    """
    return TutteSystem(F, fixed).solve(X, W)


def planar_signed_areas(Y, F):
    """Signed areas of the planar triangles ``Y[F]`` ((f,) float64; > 0 counter-clockwise)."""
    a, b, c = Y[F[:, 0]], Y[F[:, 1]], Y[F[:, 2]]
    return 0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))


def reweighted_tutte(X, F, fixed, W0, shortfall, *, iters=300, gamma_w=0.5, overshoot=2.0,
                     smooth=3, min_log_weight=-700.0):
    """Tutte embedding of a planar patch's free vertices, reweighted until no face is too small.

    Each iteration solves the Tutte system (:class:`TutteSystem`, set up once) and asks
    ``shortfall(Y)`` for each face's ratio ``q`` to the size it needs (``q >= 1``
    is enough).  Where ``q < 1``, a per-vertex conductivity ``g`` is lowered,
    ``log g_v += gamma_w log(min(q_f / overshoot, 1))`` over the faces ``f`` at
    ``v``, smoothed ``smooth`` times (a vertex only goes down, toward the mean of
    its neighbors), and the weights become ``w_ij = W0_ij sqrt(g_i g_j)``: the
    edges of small faces pull less, so the crowded part of the patch expands.
    With positive weights and a convex boundary every embedding is fold-free;
    with a non-convex boundary it may not be, and the iteration stops there.

    Parameters
    ----------
    X : (k, 2) float64 array
        Chart positions; the rows of ``fixed`` vertices are the boundary.
    F : (f, 3) int64 array
        The patch's faces, positively oriented in the chart.
    fixed : (k,) bool array
        Boundary vertices.
    W0 : (e, 2) float64 array
        Positive weights of the edges ``igl.edges(F)``, ``i -> j`` and ``j -> i``.
    shortfall : callable
        ``shortfall(Y) -> (f,) array`` of ``q`` per face.
    iters : int
        Most Tutte solves.
    gamma_w : float
        Exponent of the conductivity update.
    overshoot : float
        Aim ``q`` at this instead of 1 (the update fades as ``q`` approaches it).
    smooth : int
        Smoothing passes of ``log g`` per iteration.
    min_log_weight : float
        Floor of ``log g`` (weights stay positive in float64).

    Returns
    -------
    (k, 2) float64 array or None
        The first fold-free embedding with every ``q >= 1``; else the fold-free
        one with the fewest faces short; None when the first embedding folds.
    """
    n = X.shape[0]
    system = TutteSystem(F, fixed, repeated=True)
    E = system.E
    nb = _filled(system.A, np.ones(2 * E.shape[0]))  # the adjacency: A's pattern, all ones
    degree = np.diff(nb.indptr).astype(np.float64)
    logg, w = np.zeros(n), W0
    best, best_short = None, 0
    for _ in range(iters):
        Y = system.solve(X, w)
        if not np.all(planar_signed_areas(Y, F) > 0):
            return best
        q = shortfall(Y)
        short = int(np.count_nonzero(q < 1.0))
        if best is None or short <= best_short:
            best, best_short = Y, short
        if short == 0:
            return Y
        qv = np.ones(n)
        np.minimum.at(qv, F.ravel(), np.repeat(np.minimum(q / overshoot, 1.0), 3))
        logg = np.maximum(logg + gamma_w * np.log(qv), min_log_weight)
        for _ in range(smooth):
            logg = np.minimum(logg, 0.5 * (logg + (nb @ logg) / degree))
        w = np.maximum(W0 * np.exp(0.5 * (logg[E[:, 0]] + logg[E[:, 1]]))[:, None], 1e-300)
    return best

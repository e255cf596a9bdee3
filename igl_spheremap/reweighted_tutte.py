"""Tutte embeddings of a planar disk whose weights are lowered where faces are too small (issue #15)."""

import igl
import numpy as np
import scipy.sparse as sp


def reweighted_tutte(X, F, fixed, W0, shortfall, *, iters=300, gamma_w=0.5, overshoot=2.0,
                     smooth=3, min_log_weight=-700.0):
    """Tutte embedding of a planar patch's free vertices, reweighted until no face is too small.

    Each iteration solves the Tutte system (every free vertex at the
    ``w``-weighted average of its neighbors, ``fixed`` vertices held) and asks
    ``shortfall(Y)`` for each face's ratio ``q`` to the size it needs (``q >= 1``
    is enough).  Where ``q < 1``, a per-vertex conductivity ``g`` is lowered,
    ``log g_v += gamma_w log(min(q_f / overshoot, 1))`` over the faces ``f`` at
    ``v``, smoothed ``smooth`` times (a vertex only goes down, toward the mean of
    its neighbors), and the weights become ``w_ij = W0_ij sqrt(g_i g_j)``: the
    edges of small faces pull less, so the crowded part of the patch expands.
    With positive weights and a convex boundary every embedding is fold-free
    (Tutte; Floater 2003); with a non-convex boundary it may not be, and the
    iteration stops there.

    Parameters
    ----------
    X : (k, 2) float64 array
        Chart positions; the rows of ``fixed`` vertices are the boundary.
    F : (f, 3) int64 array
        The patch's faces, positively oriented in the chart.
    fixed : (k,) bool array
        Boundary vertices.
    W0 : (e, 2) float64 array
        Positive weights of the edges ``igl.edges(F)``, ``i -> j`` and ``j -> i``
        (e.g. :func:`igl_spheremap.mean_value_weights.mean_value_weights`).
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
    E = igl.edges(F)
    rows, cols = np.r_[E[:, 0], E[:, 1]], np.r_[E[:, 1], E[:, 0]]
    nb = sp.csr_matrix((np.ones(rows.size), (rows, cols)), shape=(n, n))
    degree = np.asarray(nb.sum(axis=1)).ravel()
    free = ~fixed
    logg, w = np.zeros(n), W0
    best, best_short = None, 0
    for _ in range(iters):
        Y = _tutte(X, w, rows, cols, free)
        if not np.all(_signed_areas(Y, F) > 0):
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


def _tutte(X, w, rows, cols, free):
    """Solve ``sum_j w_ij (Y_i - Y_j) = 0`` for the free vertices, the others at ``X``."""
    from scipy.sparse.linalg import spsolve

    n = X.shape[0]
    A = sp.csr_matrix((np.r_[w[:, 0], w[:, 1]], (rows, cols)), shape=(n, n))
    Lw = (sp.diags(np.asarray(A.sum(axis=1)).ravel()) - A).tocsr()
    Y = X.copy()
    Y[free] = spsolve(Lw[free][:, free].tocsc(), -Lw[free][:, ~free] @ X[~free])
    return Y


def _signed_areas(Y, F):
    a, b, c = Y[F[:, 0]], Y[F[:, 1]], Y[F[:, 2]]
    return 0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))

"""A spherical map that is fold-free by construction: the punctured Tutte embedding, lifted
stereographically (not in the paper; a start for meshes whose rounds cannot be trusted).

1. Puncture the closed genus-0 mesh at a vertex ``v`` (:func:`puncture_vertex`): the
   faces around ``v`` go, leaving a disk bounded by the link polygon of ``v``.
2. Put the link polygon on the unit circle (convex, around the origin) and every
   other vertex at a positively weighted average of its neighbours: by Tutte's
   theorem every face of the disk is positively oriented (W. T. Tutte, "How to draw
   a graph", Proc. London Math. Soc. 13, 1963; M. S. Floater, "One-to-one piecewise
   linear mappings over triangulations", Math. Comp. 72, 2003).
3. Scale the plane by ``lam`` and lift it to the unit sphere by the inverse
   stereographic projection ``p -> (2 p, |p|^2 - 1) / (|p|^2 + 1)``; ``v`` goes to the pole.

Orientation of the chordal image triangles: a planar circle of centre ``c`` and
radius ``rho`` lifts to the circle in which a plane cuts the sphere, and the
signed volume ``det[U_i, U_j, U_k]`` changes sign only where that plane passes
through the origin, when the origin's power ``|c|^2 - rho^2`` with respect to the
triangle's circumcircle reaches ``-1``.  Scaling by ``lam`` scales every power by
``lam^2``, so with ``lam^2 min_f power_f > -1`` every face keeps the positive sign
it has in the plane, and the faces around ``v`` are positive because the link
polygon contains the origin.  In floating point the guarantee is as good as the
crowding allows: a long shape crowds geometrically toward the middle of the disk.
"""

import igl
import numpy as np
import scipy.sparse as sp

from ..mesh.operators import mean_value_weights, vertex_areas
from ..sphere.chart import planar_signed_areas, tutte_embedding
from ..sphere.folds import count_folds, map_degree
from ..sphere.mobius import mobius_center

#: Positive edge weights of the Tutte embedding, tried in this order by the
#: guaranteed path (:mod:`igl_spheremap.folding.guaranteed`): the cotangent
#: weights made positive (the discrete conformal map wherever they are positive),
#: Floater's mean value weights, Tutte's uniform weights.
TUTTE_WEIGHTS = ("cotan_positive", "mean_value", "uniform")

#: ``lam`` keeps ``lam^2 min_f power_f`` above ``-POWER_BOUND`` (below 1: see the module docstring).
POWER_BOUND = 0.5


def puncture_vertex(V, F):
    """The vertex in the middle of an approximate geodesic diameter of the mesh (int).

    Two Dijkstra sweeps over the edge graph (edge lengths) find the ends ``a, b``
    of a long shortest path; the puncture goes where the distances to both ends
    are equal and their sum is least, so that each half of a long shape crowds
    only half as far from the pole.
    """
    from scipy.sparse.csgraph import dijkstra

    E = igl.edges(F)
    w = np.linalg.norm(V[E[:, 0]] - V[E[:, 1]], axis=1)
    n = V.shape[0]
    G = sp.csr_matrix((np.r_[w, w], (np.r_[E[:, 0], E[:, 1]], np.r_[E[:, 1], E[:, 0]])),
                      shape=(n, n))
    a = int(np.argmax(dijkstra(G, indices=0)))
    da = dijkstra(G, indices=a)
    db = dijkstra(G, indices=int(np.argmax(da)))
    return int(np.argmin(np.abs(da - db) + 0.5 * (da + db - da.max())))


def tutte_weights(V, F, E, kind):
    """Positive weights ``w_ij, w_ji`` ((e, 2) float64) of the edges ``E`` of ``(V, F)``.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int64 array
    E : (e, 2) int array
        Edges of ``F``.
    kind : {"cotan_positive", "mean_value", "uniform"}
        ``"cotan_positive"``: the cotangent weights of paper Eq. 13 floored at
        1e-2 of the median positive one (on a Delaunay mesh the embedding is then
        the discrete conformal one; a weight that is not finite, next to a face of
        zero area, gets the floor too); ``"mean_value"``:
        :func:`igl_spheremap.mesh.operators.mean_value_weights`; ``"uniform"``: 1.

    Raises
    ------
    ValueError
        Unknown ``kind``.
    """
    if kind == "uniform":
        return np.ones((E.shape[0], 2))
    if kind == "mean_value":
        return mean_value_weights(V, F, E)
    if kind == "cotan_positive":
        w = np.asarray(igl.cotmatrix(V, F).tocsr()[E[:, 0], E[:, 1]]).ravel()
        w = np.where(np.isfinite(w), w, 0.0)  # a face of zero area has no finite cotangent
        positive = w[w > 0]
        w = np.maximum(w, 1e-2 * (np.median(positive) if positive.size else 1.0))
        return np.column_stack([w, w])
    raise ValueError(f"unknown Tutte weights {kind!r}; expected one of {TUTTE_WEIGHTS}")


def tutte_disk(V, F, v, kind="mean_value"):
    """Tutte embedding of the mesh punctured at ``v``, its link polygon on the unit circle.

    The link vertices are spaced on the circle by the corner angles of ``v``'s
    faces (the polar angles a conformal map would give them), evenly when a gap
    would reach ``0.9 pi``; inscribed in the circle, the polygon is convex.

    Returns
    -------
    X : (n, 2) float64 array
        Planar positions, counter-clockwise faces; row ``v`` is NaN.
    Fd : (m - k, 3) int64 array
        The faces of the disk (those without ``v``).
    """
    Fd = F[~np.any(F == v, axis=1)]
    link = np.asarray(igl.boundary_loop(Fd), dtype=np.int64)
    th = _link_angles(V, F, v, link)
    X = np.zeros((V.shape[0], 2))
    X[link] = np.column_stack([np.cos(th), np.sin(th)])
    fixed = np.zeros(V.shape[0], dtype=bool)
    fixed[link] = fixed[v] = True  # v is in no face of the disk
    X = tutte_embedding(X, Fd, fixed, tutte_weights(V, F, igl.edges(Fd), kind))
    if planar_signed_areas(X, Fd).sum() < 0:  # the loop ran clockwise: mirror
        X[:, 1] *= -1.0
    X[v] = np.nan
    return X, Fd


def _link_angles(V, F, v, link):
    """Polar angles of the link vertices: cumulative corner angles at ``v``, scaled to ``2 pi``."""
    k = link.size
    even = 2.0 * np.pi * np.arange(k) / k
    pos = {int(a): i for i, a in enumerate(link)}
    star = F[np.any(F == v, axis=1)]
    angles = igl.internal_angles(V, star)
    gap = np.zeros(k)
    for f, row in enumerate(star):
        c = int(np.flatnonzero(row == v)[0])
        ia, ib = pos.get(int(row[(c + 1) % 3])), pos.get(int(row[(c + 2) % 3]))
        if ia is None or ib is None:
            return even
        if ib == (ia + 1) % k:
            gap[ia] = angles[f, c]
        elif ia == (ib + 1) % k:
            gap[ib] = angles[f, c]
        else:
            return even
    if not np.all(gap > 0):
        return even
    gap *= 2.0 * np.pi / gap.sum()
    return even if gap.max() >= 0.9 * np.pi else np.r_[0.0, np.cumsum(gap)[:-1]]


def circumcircle_powers(X, F):
    """Power ``|c|^2 - rho^2`` of the origin w.r.t. each planar triangle's circumcircle ((m,) float64).

    ``-inf`` for a degenerate (collinear) triangle.
    """
    a, b, c = X[F[:, 0]], X[F[:, 1]], X[F[:, 2]]
    bx, by, cx, cy = b[:, 0] - a[:, 0], b[:, 1] - a[:, 1], c[:, 0] - a[:, 0], c[:, 1] - a[:, 1]
    d = 2.0 * (bx * cy - by * cx)
    b2, c2 = bx * bx + by * by, cx * cx + cy * cy
    with np.errstate(divide="ignore", invalid="ignore"):
        ux, uy = (cy * b2 - by * c2) / d, (bx * c2 - cx * b2) / d
        centre = a + np.column_stack([ux, uy])
        p = (centre * centre).sum(axis=1) - (ux * ux + uy * uy)
    p[~np.isfinite(p)] = -np.inf
    return p


def inverse_stereographic(X, v, lam):
    """``lam X`` lifted to the unit sphere, ``v`` at the pole ``(0, 0, 1)`` ((n, 3) unit rows)."""
    P = lam * X
    r2 = (P * P).sum(axis=1)
    U = np.column_stack([2.0 * P[:, 0], 2.0 * P[:, 1], r2 - 1.0]) / (r2 + 1.0)[:, None]
    U[v] = (0.0, 0.0, 1.0)
    return U / np.linalg.norm(U, axis=1, keepdims=True)


def tutte_sphere_map(V, F, kind="cotan_positive"):
    """The punctured Tutte embedding of ``(V, F)``, lifted to the sphere: fold-free by construction.

    :func:`tutte_disk` at :func:`puncture_vertex`, lifted by :func:`lift_disk`.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int64 array
        A validated mesh (closed, genus 0, outward oriented).
    kind : {"cotan_positive", "mean_value", "uniform"}
        The weights (:func:`tutte_weights`).

    Returns
    -------
    U : (n, 3) float64 array
        Unit rows; fold-free in exact arithmetic (count its folds in floating point).
    info : dict
        ``v`` (puncture vertex), ``lam``, ``min_power``, ``centered``.
    """
    v = puncture_vertex(V, F)
    X, Fd = tutte_disk(V, F, v, kind)
    return lift_disk(V, F, X, Fd, v)


def fold_free_tutte_maps(V, F):
    """The :func:`tutte_sphere_map` of each of :data:`TUTTE_WEIGHTS`, in order, that is fold-free
    in floating point (a generator of (n, 3) float64 arrays; ``V``, ``F`` a validated mesh)."""
    for kind in TUTTE_WEIGHTS:
        U, _ = tutte_sphere_map(V, F, kind)
        if count_folds(F, U) == 0:
            yield U


def lift_disk(V, F, X, Fd, v):
    """A planar disk of ``(V, F)`` punctured at ``v``, lifted to the sphere (module doc, step 3).

    ``lam`` sends the area-weighted median radius of the disk to the equator, as
    far as the power bound (:data:`POWER_BOUND`) allows; the map is then
    Möbius-centred (:func:`igl_spheremap.mobius_center`) unless that folds a face.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int64 array
        The validated mesh.
    X : (n, 2) float64 array
        Planar positions of the disk's vertices (row ``v`` unused), counter-clockwise faces.
    Fd : (m - k, 3) int64 array
        The faces of the disk (those without ``v``).
    v : int
        The puncture vertex, sent to the pole.

    Returns
    -------
    U : (n, 3) float64 array
        Unit rows; positive faces wherever the planar faces are (in exact arithmetic).
    info : dict
        ``v``, ``lam``, ``min_power``, ``centered``.
    """
    X = X.copy()
    X[v] = np.nan
    pmin = float(circumcircle_powers(X, Fd).min())
    r = np.hypot(X[:, 0], X[:, 1])
    ok = np.isfinite(r)
    order = np.argsort(r[ok])
    cw = np.cumsum(vertex_areas(V, F)[ok][order])
    lam = 1.0 / max(r[ok][order][np.searchsorted(cw, 0.5 * cw[-1])], 1e-300)
    if pmin < 0:
        lam = min(lam, float(np.sqrt(POWER_BOUND / -pmin)))
    U = inverse_stereographic(X, v, lam)
    if map_degree(F, U) < 0:  # the lift reversed the orientation: mirror
        U[:, 0] *= -1.0
    Uc, _ = mobius_center(U, vertex_areas(V, F))
    centered = bool(np.all(np.isfinite(Uc)) and count_folds(F, Uc) <= count_folds(F, U))
    return (Uc if centered else U), dict(v=v, lam=float(lam), min_power=pmin, centered=centered)

"""One patch of :func:`igl_spheremap.inflate.inflate_crowding`: chart, reweighted Tutte, back to the sphere."""

import igl
import numpy as np

from .mean_value_weights import mean_value_weights
from .precision import SAFETY, unit_roundoff, volumes_and_margins
from .reweighted_tutte import reweighted_tutte
from .untangle import _chart


def margin_ratio(F, U, precision):
    """Per face ``s / margin``: signed image volume over rounding margin ((m,) float64)."""
    s, margin = volumes_and_margins(F, U, unit_roundoff(precision))
    return s / margin


def floor_areas(F, U, gamma, precision):
    """Image areas of the faces, and the areas they need to reach ``gamma`` times their margin.

    Scaling a face by ``lam`` gives ``s = lam^2 s0`` and margin
    ``SAFETY (u lam P0 + 3 u^2)`` (``P0`` its chord perimeter; ``u^3`` left out),
    so ``lam`` solves ``s0 lam^2 - g u P0 lam - 3 g u^2 = 0`` with
    ``g = gamma * SAFETY``.  Faces already there need their own area.

    Returns
    -------
    area, need : (m,) float64 arrays
        ``max(s, 0) / 2`` and ``s0 max(lam, 1)^2 / 2`` (``s = 2 * area`` for a
        small face on the unit sphere).
    """
    u = unit_roundoff(precision)
    s = volumes_and_margins(F, U, 0.0)[0]
    s0 = np.maximum(s, 1e-300)
    A, B, C = U[F[:, 0]], U[F[:, 1]], U[F[:, 2]]
    P0 = (np.linalg.norm(A - B, axis=1) + np.linalg.norm(B - C, axis=1)
          + np.linalg.norm(C - A, axis=1))
    g = gamma * SAFETY
    lam = (g * u * P0 + np.sqrt((g * u * P0) ** 2 + 12.0 * s0 * g * u * u)) / (2.0 * s0)
    return np.maximum(s, 0.0) / 2.0, 0.5 * s0 * np.maximum(lam, 1.0) ** 2


def try_patch(V, F, U, inside, VF, ctx):
    """Re-embed the patch of the faces at the vertices ``inside``.

    The patch (a disk) goes to the plane tangent at its mean direction by the
    gnomonic projection, which keeps every triangle's orientation in the open
    hemisphere; its interior is re-embedded by
    :func:`igl_spheremap.reweighted_tutte.reweighted_tutte` with the mean value
    weights of the input mesh, its boundary held, and projected back.

    Parameters
    ----------
    V : (n, 3) float64 array
        Input vertex positions (the weights' geometry).
    F : (m, 3) int64 array
        Faces, outward oriented.
    U : (n, 3) float64 array
        The map, unit rows.
    inside : (n,) bool array
        The grown cluster; the patch is every face at one of its vertices.
    VF : (n, m) scipy.sparse.csr_matrix
        Vertex-face incidence.
    ctx : dict
        ``precision``, ``gamma`` (the floor, in margins), ``iters``, ``gamma_w``,
        ``overshoot``.

    Returns
    -------
    tuple or str
        ``(verts, Z, fixed, faces)``: the patch's vertices, their new unit
        positions, its boundary mask and its faces; or why not (str).
    """
    pa = _patch_arrays(F, U, inside, VF)
    if pa is None:
        return "patch is not a disk"
    faces, verts, Fl, fixed = pa
    P = U[verts]
    c = P.sum(axis=0)
    c /= np.linalg.norm(c)
    h = P @ c
    if h.min() <= 0.02:  # the gnomonic chart keeps orientations up to ~89 degrees out
        return "patch does not fit in one chart"
    e1, e2 = _chart(c)
    Q = P / h[:, None]
    X = np.column_stack([Q @ e1, Q @ e2])
    W0 = mean_value_weights(V, F, verts[igl.edges(Fl)])
    u, gamma = unit_roundoff(ctx["precision"]), ctx["gamma"]

    def to_sphere(Y):
        Z = c + np.outer(Y[:, 0], e1) + np.outer(Y[:, 1], e2)
        return Z / np.linalg.norm(Z, axis=1, keepdims=True)

    def shortfall(Y):
        s, margin = volumes_and_margins(Fl, to_sphere(Y), u)
        return np.sqrt(np.maximum(s, 0.0) / (gamma * margin))

    Y = reweighted_tutte(X, Fl, fixed, W0, shortfall, iters=ctx["iters"],
                         gamma_w=ctx["gamma_w"], overshoot=ctx["overshoot"])
    if Y is None:
        return "first Tutte embedding folds (non-convex boundary)"
    return verts, to_sphere(Y), fixed, faces


def _patch_arrays(F, U, inside, VF):
    """Faces, vertices, local faces and boundary mask of the patch around ``inside``, or None.

    None when the patch is not a disk with one boundary loop, or when a vertex
    of ``inside`` lies on that loop.
    """
    members = np.flatnonzero(inside)
    faces = np.unique(VF[members].indices)
    Fp = F[faces]
    verts = np.unique(Fp)
    local = -np.ones(U.shape[0], dtype=np.int64)
    local[verts] = np.arange(verts.size)
    Fl = local[Fp]
    if verts.size - igl.edges(Fl).shape[0] + Fl.shape[0] != 1:
        return None
    loops = igl.boundary_loop_all(Fl)
    if len(loops) != 1:
        return None
    fixed = np.zeros(verts.size, dtype=bool)
    fixed[np.asarray(loops[0], dtype=np.int64)] = True
    if np.any(fixed & inside[verts]):
        return None
    return faces, verts, Fl, fixed

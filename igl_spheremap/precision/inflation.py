"""Inflate the crowded clusters of a fold-free map above their float32 rounding margin.

Thin features crowd exponentially in any harmonic map (a tube's rings shrink by
a constant factor per ring), so neither Algorithm 1 under the barrier nor plain
Tutte patches lift them above the float32 margin.  Here each connected cluster
of crowded faces (signed image volume below ``gamma`` times the margin) is grown
by edge rings until its border faces are well above their margin and its image
has room for what the crowded faces need; the patch goes to the tangent plane by
the gnomonic projection (which keeps every triangle's orientation), its interior
is re-embedded by :func:`igl_spheremap.sphere.chart.reweighted_tutte` with
Floater's mean value weights of the input mesh, and comes back to the sphere.
A patch is kept only if it folds nothing and leaves fewer faces below the floor.
Deep, nested crowding (fingers on a hand) is lifted in levels of ``level_step``
in ``s / margin``, deepest first, so that each level needs a moderate range of
Tutte weights.
"""

import igl
import numpy as np
import scipy.sparse.csgraph as csgraph

from ..errors import plural
from ..mesh.operators import mean_value_weights
from ..mesh.topology import fill_holes, grow_region, vertex_adjacency, vertex_face_incidence
from ..sphere.chart import GnomonicChart, disk_patch, reweighted_tutte
from ..sphere.folds import SAFETY, unit_roundoff, volumes_and_margins


def inflate_crowding(V, F, U, precision="float32", *, gamma=2.0, boundary_gamma=100.0,
                     area_factor=1e6, gamma_w=0.5, overshoot=2.0, level_step=1e3, max_passes=2,
                     room_growth=100.0, iters=300):
    """Re-embed the crowded clusters of a fold-free map so their faces clear ``gamma`` times the margin.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int64 array
        The validated, outward-oriented mesh.
    U : (n, 3) float64 array
        A fold-free map (unit rows).
    precision : {"float32", "float64"}
        Whose rounding margin (:func:`igl_spheremap.sphere.folds.rounding_margin`).
    gamma : float
        Faces below ``gamma`` times their margin are crowded; the patches aim there.
    boundary_gamma : float
        A patch's border faces must be at least this many times their margin.
    area_factor : float
        A patch's image area must be this many times the extra area its faces need.
    gamma_w, overshoot, iters
        Of :func:`igl_spheremap.sphere.chart.reweighted_tutte`.
    level_step : float
        Deep crowding is lifted in steps of this factor in ``s / margin``.
    max_passes : int
        Passes per level; a later pass asks ``room_growth`` times more room.

    Returns
    -------
    U : (n, 3) float64 array
        The map with the kept patches replaced (a copy); fold-free.
    clusters : list of dict
        Per cluster tried: ``vertices``, ``tried`` (rings, outcome), ``result``,
        ``level``, ``pass``.
    """
    U = np.array(U, dtype=np.float64, copy=True)
    kw = dict(area_factor=area_factor, gamma_w=gamma_w, overshoot=overshoot, iters=iters)
    info = []

    def run(levels):
        nonlocal U
        for level in levels:
            for p in range(max_passes):
                U, recs = _inflate_pass(V, F, U, precision, level, p, dict(
                    kw, room=room_growth ** p, boundary=boundary_gamma * level / gamma))
                info.extend(recs)
                if not any(rec["result"].startswith("kept") for rec in recs):
                    break
                if not np.any(margin_ratio(F, U, precision) < min(level, 1.0)):
                    break

    run([gamma])
    r0 = margin_ratio(F, U, precision)
    if level_step and np.any(r0 < 1.0):
        levels = [gamma]
        while r0.min() < levels[0] / level_step:
            levels.insert(0, levels[0] / level_step)
        run(levels)
    return U, info


def _inflate_pass(V, F, U, precision, gamma, p, kw):
    """One pass over the clusters of faces below ``gamma`` times the margin."""
    n = U.shape[0]
    A = vertex_adjacency(F, n)
    VF = vertex_face_incidence(F, n)
    r = margin_ratio(F, U, precision)
    crowded = np.zeros(n, dtype=bool)
    crowded[F[r < gamma].ravel()] = True
    ncomp, labels = csgraph.connected_components(A[crowded][:, crowded], directed=False)
    idx = np.flatnonzero(crowded)
    info = []
    for comp in range(ncomp):
        inside = np.zeros(n, dtype=bool)
        inside[idx[labels == comp]] = True
        if not np.any(r[np.unique(VF[np.flatnonzero(inside)].indices)] < min(1.0, gamma)):
            continue  # crowded, but above this level already
        rec = dict(vertices=int(inside.sum()), tried=[], result="", level=gamma, **{"pass": p})
        ctx = dict(V=V, F=F, A=A, VF=VF, precision=precision, gamma=gamma, **kw)
        U, r = _grow_and_embed(U, r, inside, rec, ctx)
        info.append(rec)
    return U, info


def _grow_and_embed(U, r, inside, rec, ctx, max_patch=0.25, max_tries=4, max_rings=200):
    """Grow one cluster ring by ring; re-embed it when it has room.  Returns ``(U, r)``."""
    F, A, VF, gamma = ctx["F"], ctx["A"], ctx["VF"], ctx["gamma"]
    n, floor = U.shape[0], min(1.0, ctx["gamma"])
    s_area, need = floor_areas(F, U, gamma, ctx["precision"])
    for ring in range(1, max_rings + 1):
        grown = fill_holes(A, grow_region(A, inside))
        if grown.sum() == inside.sum() or grown.sum() > max_patch * n:
            rec["result"] = f"no room: the patch would cover more than {max_patch:.0%} of the mesh"
            break
        inside = grown
        faces = np.unique(VF[np.flatnonzero(inside)].indices)
        border = faces[~np.all(inside[F[faces]], axis=1)]
        if r[border].min() < ctx["boundary"]:
            continue
        if s_area[faces].sum() < ctx["area_factor"] * ctx["room"] * np.sum(need[faces] - s_area[faces]):
            continue
        if rec["tried"] and ring - rec["tried"][-1][0] < 3:
            continue  # retry a failed patch only every third ring
        if len(rec["tried"]) >= max_tries:
            break
        out = try_patch(ctx["V"], F, U, inside, VF, ctx)
        rec["tried"].append((ring, out if isinstance(out, str) else "ok"))
        if isinstance(out, str):
            rec["result"] = out
            if out.startswith("first Tutte"):
                continue  # a wider patch has a rounder boundary
            break
        verts, Z, fixed, faces = out
        old = U[verts].copy()
        before = int(np.count_nonzero(r[faces] < floor))
        U[verts[~fixed]] = Z[~fixed]
        r_new = margin_ratio(F, U, ctx["precision"])
        after = int(np.count_nonzero(r_new[faces] < floor))
        if (r_new[faces] <= 0).any() or after >= before:
            U[verts] = old
            rec["result"] = f"rejected ({before} -> {after} below the floor)"
            continue
        rec["result"] = (f"kept ({before} -> {after} below {floor:.0e} x margin, patch of "
                         f"{verts.size} vertices, {plural(ring, 'ring')})")
        return U, r_new
    return U, r


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
    :func:`igl_spheremap.sphere.chart.reweighted_tutte` with the mean value
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
    faces = np.unique(VF[np.flatnonzero(inside)].indices)
    patch = disk_patch(F, faces, inside)
    if patch is None:
        return "patch is not a disk"
    verts, Fl, fixed = patch
    P = U[verts]
    chart = GnomonicChart.around(P)
    if not chart.fits(P):
        return "patch does not fit in one chart"
    X = chart.to_plane(P)
    W0 = mean_value_weights(V, F, verts[igl.edges(Fl)])
    u, gamma = unit_roundoff(ctx["precision"]), ctx["gamma"]

    def shortfall(Y):
        s, margin = volumes_and_margins(Fl, chart.to_sphere(Y), u)
        return np.sqrt(np.maximum(s, 0.0) / (gamma * margin))

    Y = reweighted_tutte(X, Fl, fixed, W0, shortfall, iters=ctx["iters"],
                         gamma_w=ctx["gamma_w"], overshoot=ctx["overshoot"])
    if Y is None:
        return "first Tutte embedding folds (non-convex boundary)"
    return verts, chart.to_sphere(Y), fixed, faces

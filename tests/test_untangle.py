"""igl_spheremap.folding.untangle.untangle_folds: Tutte patches and kernel sweeps around folded faces."""

import igl
import numpy as np
import pytest

from igl_spheremap import count_folds, folded_faces
from igl_spheremap.sphere.chart import tangent_basis as _chart
from igl_spheremap.folding.untangle import _kernel_moves, _sweep_groups, untangle_folds, untangle_patches
from igl_spheremap.mesh.topology import vertex_face_incidence

from conftest import drag_past_neighbor


def _rings(F, n, seeds, k):
    """Vertices within k edge rings of the seeds (igl.adjacency_matrix)."""
    A = igl.adjacency_matrix(F).tocsr()
    inside = np.zeros(n, dtype=bool)
    inside[seeds] = True
    for _ in range(k):
        inside |= (A @ inside.astype(np.float64)) > 0
    return inside


def test_one_folded_patch_is_untangled_locally(icosphere):
    V, F = icosphere(3)
    U = drag_past_neighbor(F, V, 100)
    before = U.copy()
    assert count_folds(F, U) > 0
    out, remaining = untangle_folds(F, U)
    assert np.array_equal(U, before)  # the input is not modified
    assert remaining == 0 == count_folds(F, out)
    assert np.abs(np.linalg.norm(out, axis=1) - 1.0).max() < 1e-14
    changed = np.any(out != U, axis=1)
    assert changed[100]
    # Outside the patch (a few rings around the folded faces) nothing moves.
    patch = _rings(F, V.shape[0], F[folded_faces(F, U)].ravel(), 3)
    assert not changed[~patch].any()
    assert np.array_equal(out[~patch], U[~patch])


def test_two_separate_patches(icosphere):
    V, F = icosphere(3)
    far = int(np.argmin(V @ V[100]))  # the antipode of vertex 100
    U = drag_past_neighbor(F, drag_past_neighbor(F, V, 100), far, 1.8)
    seeds = F[folded_faces(F, U)].ravel()
    assert {100, far} <= set(seeds.tolist())
    out, remaining = untangle_folds(F, U)
    assert remaining == 0 == count_folds(F, out)
    changed = np.any(out != U, axis=1)
    assert not changed[~_rings(F, V.shape[0], seeds, 3)].any()


def test_real_map_with_a_local_fold(conformal_map):
    V, F, result, _ = conformal_map("goathead.obj")
    assert result.folds == 0
    U = drag_past_neighbor(F, result.U, 1000, 3.0)
    assert count_folds(F, U) > 0
    out, remaining = untangle_folds(F, U)
    assert remaining == 0 == count_folds(F, out)
    changed = np.any(out != U, axis=1)
    assert changed.sum() < 100
    assert not changed[~_rings(F, V.shape[0], F[folded_faces(F, U)].ravel(), 12)].any()


def test_fold_free_input_is_returned_as_a_copy(icosphere):
    V, F = icosphere(2)
    out, remaining = untangle_folds(F, V)
    assert remaining == 0 and out is not V and np.array_equal(out, V)


def test_a_map_that_is_not_one_is_refused(icosphere):
    """A NaN row was returned as is with 0 folds reported (count_folds then refuses the map);
    faces indexing past the map, or a map short of a row, raised scipy's index errors."""
    V, F = icosphere(2)
    with pytest.raises(ValueError, match="1 row with NaN"):
        untangle_folds(F, np.r_[[[np.nan] * 3], V[1:]])
    with pytest.raises(ValueError, match=r"F has 5 indices outside 0\.\.161"):
        untangle_folds(np.where(F == 0, 999, F), V)
    with pytest.raises(ValueError, match=r"F has \d+ indices outside 0\.\.160"):
        untangle_folds(F, V[:-1])


def test_vertex_flung_across_the_sphere_is_brought_back(icosphere):
    """Its star folds; the Tutte patch re-embeds it from its link alone (where it is
    now does not matter), so it lands inside its link polygon and nothing else moves."""
    V, F = icosphere(3)
    U = V.copy()
    U[100] = -U[100]
    assert count_folds(F, U) == 6
    out, remaining = untangle_folds(F, U, max_rings=3)
    assert remaining == 0 == count_folds(F, out)
    moved = np.flatnonzero(np.any(out != U, axis=1))
    assert 100 in moved
    assert np.arccos(np.clip(out[100] @ V[100], -1, 1)) < 0.1  # back among its neighbours


def test_remaining_folds_are_reported_honestly(icosphere):
    """Every vertex of the sphere mirrored: no local patch can be fold-free; what is
    left is counted (against a direct count)."""
    V, F = icosphere(2)
    out, remaining = untangle_folds(F, -V, max_rings=3)
    assert remaining == count_folds(F, out) > 0


def _star_distances(F, U, v, c, X):
    """Signed distances of chart points X (k, 2) to the link edge lines of v's star.

    Independent of the implementation: plain 2-D geometry in the gnomonic chart at c.
    """
    e1, e2 = _chart(c)
    dists = []
    for f in F[np.any(F == v, axis=1)]:
        i = int(np.flatnonzero(f == v)[0])
        a, b = U[f[(i + 1) % 3]], U[f[(i + 2) % 3]]
        pa = np.array([a @ e1, a @ e2]) / (a @ c)
        pb = np.array([b @ e1, b @ e2]) / (b @ c)
        d = pb - pa
        dists.append((d[0] * (X[:, 1] - pa[1]) - d[1] * (X[:, 0] - pa[0])) / np.linalg.norm(d))
    return np.min(dists, axis=0)


def test_kernel_move_is_the_chebyshev_center_of_the_link_kernel(icosphere):
    """The LP optimum beats every point of a fine grid, and unfolds the star."""
    V, F = icosphere(2)
    U = drag_past_neighbor(F, V, 40, 1.6)
    star = np.flatnonzero(np.any(F == 40, axis=1))
    assert folded_faces(F[star], U).any()
    moves = _kernel_moves(F, U, vertex_face_incidence(F, U.shape[0]), [40])
    p = moves[40]
    assert abs(np.linalg.norm(p) - 1.0) < 1e-14
    c = U[40]
    e1, e2 = _chart(c)
    best = _star_distances(F, U, 40, c, (np.array([[p @ e1, p @ e2]]) / (p @ c)))[0]
    s = np.linspace(-0.6, 0.6, 601)
    grid = np.stack(np.meshgrid(s, s), axis=-1).reshape(-1, 2)
    assert best > 0
    assert best >= _star_distances(F, U, 40, c, grid).max() - 1e-9
    moved = U.copy()
    moved[40] = p
    assert not folded_faces(F[star], moved).any()


def test_kernel_sweeps_alone_untangle_a_dragged_vertex(icosphere):
    """With no Tutte patches (max_rings=0) the sweeps move only the fold's vertices."""
    V, F = icosphere(3)
    U = drag_past_neighbor(F, V, 100, 1.8)
    seeds = np.unique(F[folded_faces(F, U)])
    out, remaining = untangle_folds(F, U, max_rings=0)
    assert remaining == 0 == count_folds(F, out)
    changed = np.flatnonzero(np.any(out != U, axis=1))
    assert 100 in changed
    assert set(changed.tolist()) <= set(np.flatnonzero(_rings(F, V.shape[0], seeds, 1)).tolist())


def test_fixed_vertices_never_move_while_the_rest_is_untangled(icosphere, conformal_map):
    """Hard landmarks next to a fold: untangling must leave them bit for bit."""
    V, F = icosphere(3)
    cases = [(F, drag_past_neighbor(F, V, 100), 100)]
    _, Fg, result, _ = conformal_map("goathead.obj")
    cases.append((Fg, drag_past_neighbor(Fg, result.U, 1000, 3.0), 1000))
    for F, U, v in cases:
        n = U.shape[0]
        free_out, _ = untangle_folds(F, U)
        moved_free = np.flatnonzero(np.any(free_out != U, axis=1))
        # fix every vertex the unconstrained untangling moved except the dragged
        # one, and the dragged vertex's other neighbours in the folded faces
        fixed = np.zeros(n, dtype=bool)
        fixed[moved_free] = True
        fixed[F[folded_faces(F, U)].ravel()] = True
        fixed[v] = False
        assert fixed.sum() >= 3 and np.any(free_out[fixed] != U[fixed])  # moved unless fixed
        out, remaining = untangle_folds(F, U, fixed=fixed)
        assert np.array_equal(out[fixed], U[fixed])
        assert remaining == 0 == count_folds(F, out)
        assert np.any(out[v] != U[v])


def test_folds_only_fixed_vertices_could_remove_are_left(icosphere):
    V, F = icosphere(3)
    U = drag_past_neighbor(F, V, 100)
    fixed = _rings(F, V.shape[0], [100], 2)  # the dragged vertex and two rings around it
    out, remaining = untangle_folds(F, U, fixed=fixed)
    assert np.array_equal(out[fixed], U[fixed])
    assert remaining == count_folds(F, out) == count_folds(F, U) > 0


def _crowded(U, ring, c, eps):
    """``U`` with the vertices ``ring`` pulled toward ``c`` by the factor ``eps`` in the
    gnomonic chart at ``c`` (orientations kept: the chart keeps them, and so does scaling)."""
    W = U.copy()
    W[ring] = c + eps * (U[ring] / (U[ring] @ c)[:, None] - c)
    W[ring] /= np.linalg.norm(W[ring], axis=1, keepdims=True)
    return W


def test_kernel_move_unfolds_a_star_crowded_into_a_micro_radian(icosphere):
    """The same folded star shrunk 10^6 times (as in the crowded image of a thin limb): the
    move must still unfold it, whatever the solver's absolute tolerances."""
    V, F = icosphere(2)
    star = np.flatnonzero(np.any(F == 40, axis=1))
    for eps in (1.0, 1e-4, 1e-6, 1e-8):
        U = _crowded(drag_past_neighbor(F, V, 40, 1.6), np.unique(F[star]), V[40], eps)
        assert folded_faces(F[star], U).any()
        moved = U.copy()
        moved[40] = _kernel_moves(F, U, vertex_face_incidence(F, U.shape[0]), [40])[40]
        assert not folded_faces(F[star], moved).any(), eps


def test_moves_of_non_adjacent_vertices_solved_together_equal_each_alone(icosphere):
    """The joint program is separable: its optimum is every vertex's own."""
    V, F = icosphere(3)
    A = igl.adjacency_matrix(F).tocsr()
    U = V.copy()
    verts = [100, int(np.argmin(V @ V[100])), 7]
    for v in verts:
        U = drag_past_neighbor(F, U, v, 1.6)
    assert A[verts][:, verts].nnz == 0
    VF = vertex_face_incidence(F, U.shape[0])
    together = _kernel_moves(F, U, VF, verts)
    assert sorted(together) == sorted(verts)
    for v in verts:
        alone = _kernel_moves(F, U, VF, [v])[v]
        assert np.abs(together[v] - alone).max() < 1e-12



def test_a_failed_joint_program_falls_back_to_each_vertex_alone(icosphere, monkeypatch):
    """If HiGHS fails on the joint program (forced here: a failure status for any program of
    more than one vertex), every vertex is still moved, to its own program's optimum."""
    import scipy.optimize
    V, F = icosphere(3)
    U = V.copy()
    verts = [100, int(np.argmin(V @ V[100])), 7]
    for v in verts:
        U = drag_past_neighbor(F, U, v, 1.6)
    VF = vertex_face_incidence(F, U.shape[0])
    alone = {v: _kernel_moves(F, U, VF, [v])[v] for v in verts}
    solve = scipy.optimize.linprog
    calls = []

    def failing_joint(c, **kw):
        calls.append(len(c) // 3)
        res = solve(c, **kw)
        if len(c) > 3:
            res.status = 4
        return res

    monkeypatch.setattr(scipy.optimize, "linprog", failing_joint)
    moves = _kernel_moves(F, U, VF, verts)
    assert calls == [3, 1, 1, 1]
    assert sorted(moves) == sorted(verts)
    for v in verts:
        assert np.abs(moves[v] - alone[v]).max() < 1e-12

def test_sweep_groups_are_the_ascending_order_as_a_level_schedule(icosphere):
    """Every vertex after its smaller neighbors and before its larger ones; groups hold no edge."""
    V, F = icosphere(3)
    A = igl.adjacency_matrix(F).tocsr()
    rng = np.random.default_rng(0)
    verts = np.sort(rng.choice(V.shape[0], 200, replace=False))
    groups = _sweep_groups(A, verts)
    assert np.array_equal(np.sort(np.concatenate(groups)), verts)
    rank = {int(v): i for i, g in enumerate(groups) for v in g}
    for g in groups:
        assert A[g][:, g].nnz == 0
    for v in verts:
        for u in A[v].indices:
            if u in rank:
                assert (rank[u] < rank[v]) == (u < v)


def test_within_a_few_rings_equals_the_whole_mesh_and_leaves_the_rest(icosphere, conformal_map):
    """``within``: the same untangling on the submesh around the folds, fixed beyond it."""
    V, F = icosphere(4)
    far = int(np.argmin(V @ V[100]))
    _, Fg, result, _ = conformal_map("goathead.obj")
    cases = [(F, drag_past_neighbor(F, drag_past_neighbor(F, V, 100), far, 1.8)),
             (Fg, drag_past_neighbor(Fg, result.U, 1000, 3.0))]
    for F, U in cases:
        n = U.shape[0]
        seeds = F[folded_faces(F, U)].ravel()
        whole, left = untangle_folds(F, U)
        local, left_local = untangle_folds(F, U, within=14)
        assert left_local == left == 0 == count_folds(F, local)
        assert np.array_equal(local, whole)
        # with one ring the patches are cut short: the far vertices are untouched
        tight, _ = untangle_folds(F, U, within=1)
        outside = ~_rings(F, n, seeds, 1)
        assert np.array_equal(tight[outside], U[outside])


def test_fill_holes_takes_the_largest_rest_or_the_one_reaching_outside(icosphere):
    """A band about the equator encloses the smaller cap; with ``outside`` on the larger cap's
    side only, the same; with ``outside`` in the smaller cap, the larger cap is the hole."""
    from igl_spheremap.mesh.topology import fill_holes, vertex_adjacency

    V, F = icosphere(3)
    A = vertex_adjacency(F, V.shape[0])
    band = np.abs(V[:, 2] - 0.2) < 0.15
    grown = _rings(F, V.shape[0], np.flatnonzero(band), 1)
    north, south = (V[:, 2] > 0.2) & ~grown, (V[:, 2] < 0.2) & ~grown
    assert 0 < north.sum() < south.sum()
    assert np.array_equal(fill_holes(A, band), band | grown & (V[:, 2] > 0.2) | north)
    top, bottom = (np.zeros(V.shape[0], dtype=bool) for _ in range(2))
    top[np.argmax(V[:, 2])] = bottom[np.argmin(V[:, 2])] = True
    assert np.array_equal(fill_holes(A, band, outside=bottom), fill_holes(A, band))
    filled = fill_holes(A, band, outside=top)
    assert filled[south].all() and not filled[north].any()


def _dart_star():
    """A planar star (vertex 0 and its link, counter-clockwise): a body and a thin spike
    carrying most of the link's vertices, so that their average (where a uniform Tutte
    patch puts vertex 0) lies in the spike, outside the link's kernel (near the body)."""
    body = [(0.0, 0.1), (-1.0, 1.0), (-2.0, 0.0), (-1.0, -1.0), (0.0, -0.1)]
    tip = np.array([5.0, 0.0])
    lower = [np.array(body[-1]) + t * (tip - body[-1]) for t in np.linspace(0, 1, 12)[1:]]
    upper = [tip + t * (np.array(body[0]) - tip) for t in np.linspace(0, 1, 12)[1:-1]]
    link = np.array(body + [tuple(p) for p in lower + upper])
    k = link.shape[0]
    F = np.array([[0, 1 + i, 1 + (i + 1) % k] for i in range(k)], dtype=np.int64)
    return link, F


def _on_sphere(X, s=0.1):
    """Planar points X (k, 2) on the unit sphere around the north pole (inverse gnomonic)."""
    P = np.column_stack([s * X, np.ones(len(X))])
    return P / np.linalg.norm(P, axis=1, keepdims=True)


def test_a_patch_tutte_folds_is_untangled():
    """A fold no Tutte patch removes (the link is not convex and its vertices' average is
    outside its kernel), kernel sweeps off: the untangled patch (Garanzha et al.) is
    fold-free, the link unmoved, and reported as kept; without it the fold stays."""
    link, F = _dart_star()
    centre = link.mean(axis=0)
    U = _on_sphere(np.vstack([[4.0, 0.4], link]))
    assert count_folds(F, U) > 0
    assert count_folds(F, _on_sphere(np.vstack([centre, link]))) > 0  # Tutte's place folds
    assert count_folds(F, _on_sphere(np.vstack([[-1.0, 0.0], link]))) == 0  # a fold-free place
    fixed = np.ones(U.shape[0], dtype=bool)
    fixed[0] = False
    out, remaining = untangle_folds(F, U, max_sweeps=0, fixed=fixed)
    assert remaining == count_folds(F, out) > 0
    out, remaining, patched = untangle_patches(F, U, max_sweeps=0, fixed=fixed)
    assert patched and remaining == 0 == count_folds(F, out)
    assert np.array_equal(out[1:], U[1:])
    assert abs(np.linalg.norm(out[0]) - 1.0) < 1e-14

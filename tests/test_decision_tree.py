"""The decision tree of Algorithm 2 (drawn in igl_spheremap.folding's docstring and in
docs/decision_tree.md), walked branch by branch on small constructed meshes.

Each test builds a mesh (or forces a condition) that takes one branch and checks, from
the result's own record (the rounds' kinds, starts and barrier flags, the repair tried),
that the branch ran; the maps themselves are checked against libigl's determinant-free
fold test where it matters.
"""

import pathlib
import warnings

import igl
import numpy as np
import pytest

import igl_spheremap
from igl_spheremap import SphericalMapWarning, count_folds, spherical_conformal_map
from igl_spheremap.sphere.folds import map_degree
from igl_spheremap.mesh.shapes import capsule, ellipsoid

from conftest import drag_past_neighbor, load_mesh, map_problem

DOCS = pathlib.Path(__file__).resolve().parents[1] / "docs" / "decision_tree.md"


def _quiet(V, F, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SphericalMapWarning)
        return spherical_conformal_map(V, F, **kw)


def _drawing(text):
    """The lines of the tree, from ``spherical_conformal_map(V, F)`` to the result."""
    lines = text.splitlines()
    start = next(i for i, s in enumerate(lines) if s.strip() == "spherical_conformal_map(V, F)")
    end = next(i for i in range(start, len(lines)) if "faces left below the margin" in lines[i])
    return [s.strip() for s in lines[start:end + 1]]


def test_the_drawing_in_the_docs_is_the_docstrings():
    import igl_spheremap.folding as folding

    assert _drawing(DOCS.read_text()) == _drawing(folding.__doc__)


# ------------------------------------------------------------------------- round 0

def test_fold_free_gauss_map_runs_round_0_under_the_barrier():
    V, F = ellipsoid(3.0)  # convex: its Gauss map is fold-free
    r = _quiet(V, F)
    (r0,) = r.rounds
    assert r0.kind == "gauss" and r0.folds_before == 0 and r0.fold_barrier
    assert r.success


def test_folded_gauss_map_runs_round_0_free():
    V, F = capsule(5.0)  # the cylinder's rings all map to the equator
    r = _quiet(V, F)
    r0 = r.rounds[0]
    assert r0.kind == "gauss" and r0.folds_before > 0 and not r0.fold_barrier


def test_paper_method_runs_no_barrier_and_no_centering():
    V, F = ellipsoid(3.0)
    r = _quiet(V, F, method="paper", max_iter=200)
    assert not any(rnd.fold_barrier for rnd in r.rounds)
    assert np.array_equal(r.U, r.rounds[-1].U)  # no final centering
    opts = r.options
    assert not (opts.fold_barrier or opts.untangle or opts.local_repair or opts.round_guard
                or opts.mobius or opts.guaranteed_path)


# ------------------------------------------------------------------------- the rounds

def _fold_round_0(monkeypatch, F, vertex=100):
    """Make round 0's Algorithm 1 end with a few folded faces around one vertex."""
    import igl_spheremap.folding.problem as problem

    real, calls = problem.minimize, []

    def folds_first(*args, **kw):
        res = real(*args, **kw)
        if not calls:
            res.U = drag_past_neighbor(F, res.U, vertex, 2.5)
            res.folds = count_folds(F, res.U)
        calls.append(1)
        return res

    monkeypatch.setattr(problem, "minimize", folds_first)


def test_isolated_folds_after_round_0_get_a_local_round(icosphere, monkeypatch):
    V, F = icosphere(4)
    V = V * np.array([1.0, 1.2, 0.8])
    _fold_round_0(monkeypatch, F)
    r = _quiet(V, F)
    assert [rnd.kind for rnd in r.rounds] == ["gauss", "local"]
    assert r.rounds[1].fold_barrier and r.success


def test_without_local_repair_the_folds_go_to_a_star_round_under_the_barrier(icosphere,
                                                                              monkeypatch):
    V, F = icosphere(4)
    V = V * np.array([1.0, 1.2, 0.8])
    _fold_round_0(monkeypatch, F)
    r = _quiet(V, F, local_repair=False)
    star = r.rounds[1]
    assert star.kind == "star" and star.folds_before == 0 and star.fold_barrier


def _folded_star_map(monkeypatch, F):
    """Make every star map fold a few faces around one vertex."""
    import igl_spheremap.folding.rounds as rounds

    real = rounds.star_map_of

    def folded(*args, **kw):
        S, Phi, lam, reflected = real(*args, **kw)
        return drag_past_neighbor(F, S, 100, 2.5), Phi, lam, reflected

    monkeypatch.setattr(rounds, "star_map_of", folded)


@pytest.mark.parametrize("untangle", [True, False])
def test_the_star_maps_folds_are_untangled_then_the_barrier_applies(icosphere, monkeypatch,
                                                                     untangle):
    V, F = icosphere(4)
    V = V * np.array([1.0, 1.2, 0.8])
    _fold_round_0(monkeypatch, F)
    _folded_star_map(monkeypatch, F)
    r = _quiet(V, F, local_repair=False, untangle=untangle)
    star = r.rounds[1]
    assert star.kind == "star" and star.folds_star > 0
    assert (star.folds_before == 0) == untangle      # untangled, or left folded
    assert star.fold_barrier == untangle             # the barrier only from a fold-free start


@pytest.mark.parametrize("guard", [True, False])
def test_a_collapsed_round_is_followed_by_a_restart_only_with_the_guard(guard):
    """Without the barrier the 30:1 ellipsoid's star round collapses the map (E/4pi < 0.5);
    with the guard the next round restarts from the Tutte map, fold-free and of degree 1."""
    V, F = ellipsoid(30.0)
    r = _quiet(V, F, fold_barrier=False, round_guard=guard, max_rounds=2)
    energies = [rnd.energy / (4 * np.pi) for rnd in r.rounds]
    assert energies[1] < 0.5 and r.rounds[1].kind == "star"
    assert ("collapsed" in r.message) == guard
    assert [x.kind for x in r.rounds][2:3] == (["restart"] if guard else ["star"])
    if guard:
        restart = r.rounds[2]
        assert count_folds(r.F, restart.U_init) == 0
        assert map_degree(r.F, restart.U) == pytest.approx(1.0)


def test_a_round_that_collapses_to_degree_0_starts_no_star_round(icosphere, monkeypatch):
    """Round 0 forced to a degree-0 map (the southern hemisphere folded onto the northern):
    no star map is built from it; the guaranteed path gives a fold-free map of degree 1."""
    import igl_spheremap.folding.problem as problem

    real, calls = problem.minimize, []

    def collapse_first(*args, **kw):
        res = real(*args, **kw)
        if not calls:
            res.U = res.U * np.where(res.U[:, 2:] < 0, [1.0, 1.0, -1.0], 1.0)
            res.folds = count_folds(args[2], res.U)
        calls.append(1)
        return res

    monkeypatch.setattr(problem, "minimize", collapse_first)
    V, F = icosphere(3)
    r = _quiet(V * np.array([1.0, 1.2, 0.8]), F)
    assert r.rounds[0].folds_after > 0 and "degree 0" in r.message
    assert not [x for x in r.rounds if x.kind == "star"]
    assert r.folds == 0 and r.degree == pytest.approx(1.0, abs=1e-9)


@pytest.mark.parametrize("guard", [True, False])
def test_rounds_that_do_not_lower_the_folds_stop_only_with_the_guard(icosphere, monkeypatch,
                                                                      guard):
    import igl_spheremap.folding.problem as problem

    real = problem.minimize
    V, F = icosphere(3)

    def always_folds(*args, **kw):  # every round ends with the same few folds
        res = real(*args, **kw)
        res.U = drag_past_neighbor(F, res.U, 100, 2.5)
        res.folds = count_folds(F, res.U)
        return res

    monkeypatch.setattr(problem, "minimize", always_folds)
    r = _quiet(V * np.array([1.0, 1.2, 0.8]), F, local_repair=False, max_rounds=4,
               guaranteed_path=False, round_guard=guard)
    kinds = [x.kind for x in r.rounds]
    assert kinds == (["gauss", "star"] if guard else ["gauss"] + ["star"] * 4)
    assert ("did not lower the fold count" in r.message) == guard


# ------------------------------------------------------------------------- the guaranteed path

def test_a_map_held_by_the_barrier_goes_to_the_guaranteed_path():
    """Split icosphere: the rounds' map is held near the Gauss map (most vertices frozen);
    one conformal descent runs from a start fold-free by construction, freezes nothing,
    and ends near the central projection's angle distortion (a near-conformal map)."""
    from igl_spheremap.folding.starts import central_projection
    from igl_spheremap.mesh.shapes import split_icosphere

    V, F = split_icosphere(2)
    reported = []
    r = _quiet(V, F, callback=reported.append)
    assert reported == r.rounds  # the guaranteed path's rounds reach the callback too
    starts = [x for x in r.rounds if x.kind in ("central", "tutte", "polish")]
    assert len(starts) == 1 and starts[0].fold_barrier and starts[0].frozen == 0
    assert r.rounds[0].frozen > 0.5 * len(V) and "guaranteed path" in r.message
    reference = igl_spheremap.angle_distortion(V, F, central_projection(V, F)).mean()
    assert igl_spheremap.angle_distortion(V, r.F, r.U).mean() <= 1.5 * reference
    assert r.success and r.folds == 0 and count_folds(r.F, r.U) == 0


def _rod(n_around=24, rings=6, length=10.0):
    """A CAD-style rod of radius 1: each end cap a polar grid of ``rings`` rings of
    ``n_around`` vertices, the side ``n_around`` strips running its whole ``length`` (two
    needle triangles each), as CAD programs triangulate a cylinder."""
    V, F = [], []
    for z, sign in ((length / 2, 1), (-length / 2, -1)):
        base = len(V)
        V.append([0.0, 0.0, z])
        a = 2 * np.pi * np.arange(n_around) / n_around
        for k in range(1, rings + 1):
            V += [[k / rings * np.cos(t), k / rings * np.sin(t), z] for t in a]
        ring = lambda k, j, b=base: b + 1 + (k - 1) * n_around + j % n_around
        cap = [[base, ring(1, j), ring(1, j + 1)] for j in range(n_around)]
        for k in range(1, rings):
            for j in range(n_around):
                cap += [[ring(k, j), ring(k + 1, j), ring(k + 1, j + 1)],
                        [ring(k, j), ring(k + 1, j + 1), ring(k, j + 1)]]
        F += cap if sign > 0 else [f[::-1] for f in cap]
    top = lambda j: 1 + (rings - 1) * n_around + j % n_around
    bottom = lambda j: top(j) + 1 + rings * n_around
    for j in range(n_around):
        F += [[top(j), bottom(j + 1), top(j + 1)], [top(j), bottom(j), bottom(j + 1)]]
    return np.array(V), np.array(F, dtype=np.int64)


def _collapsed_rod_map(V, eps=1e-2, squeeze=0.2):
    """A map of the rod of degree 1 with a harmonic energy far below a conformal map's: each
    end cap crushed to ``eps`` of its size about a pole and squeezed ``squeeze``:1 across (its
    angles distorted, as on a map Algorithm 1 collapsed), the side's needle strips spanning the
    sphere from pole to pole."""
    U = np.column_stack([eps * V[:, 0], eps * squeeze * V[:, 1], np.sign(V[:, 2])])
    return U / np.linalg.norm(U, axis=1, keepdims=True)


def _log_solid_angle_ratio(V, F, U):
    """Per face, log10 of its share of the sphere (the solid angle of its image, by Van
    Oosterom and Strackee's formula) over its share of the surface's area (libigl)."""
    a, b, c = U[F[:, 0]], U[F[:, 1]], U[F[:, 2]]
    det = np.einsum("ij,ij->i", a, np.cross(b, c))
    omega = 2.0 * np.arctan2(det, 1.0 + (a * b).sum(1) + (b * c).sum(1) + (c * a).sum(1))
    area = igl.doublearea(V, F)
    return np.log10((omega / (4.0 * np.pi)) / (area / area.sum()))


def test_a_map_collapsed_in_all_but_its_degree_goes_to_the_guaranteed_path(monkeypatch):
    """A CAD-style rod whose round 0 ends at a map of the kind Algorithm 1 from the Gauss map
    reaches on such rods (on some machines; on others rounding folds it first): fold-free, of
    degree 1, the caps' faces crushed and E/4pi far below 1 (the side's needles span the
    sphere).  That map is not returned outright, also with ``polish="never"``: the guaranteed
    path's descents run and one of them wins, with a conformal map's energy and areas (libigl's
    cotangent energy; the rod's triangles have no obtuse angle)."""
    import igl_spheremap.folding.problem as problem

    V, F = _rod()
    real, calls = problem.minimize, []

    def collapsed_first(*args, **kw):
        res = real(*args, **kw)
        if not calls:
            res.U, res.folds = _collapsed_rod_map(V), 0
        calls.append(1)
        return res

    monkeypatch.setattr(problem, "minimize", collapsed_first)
    r = _quiet(V, F, polish="never")
    L = igl.cotmatrix(V, r.F)

    def energy(U):
        return -0.5 * np.sum(U * (L @ U)) / (4 * np.pi)

    r0 = r.rounds[0]
    assert r0.kind == "gauss" and r0.folds_after == 0 and count_folds(r.F, r0.U) == 0
    assert abs(map_degree(r.F, r0.U) - 1.0) < 0.01 and energy(r0.U) < 0.2
    assert np.mean(_log_solid_angle_ratio(V, r.F, r0.U) < -1.5) > 0.9  # below 3% of its share
    assert r.success and count_folds(r.F, r.U) == 0 and "collapsed" in r.message
    assert energy(r.U) > 0.5 and np.all(_log_solid_angle_ratio(V, r.F, r.U) > -1.5)


def test_without_the_guaranteed_path_a_held_map_is_no_success():
    from igl_spheremap.mesh.shapes import split_icosphere

    V, F = split_icosphere(2)
    r = _quiet(V, F, guaranteed_path=False)
    assert r.folds == 0 and not r.success and "held" in r.message



def test_a_converged_descent_is_kept_over_a_stalled_one_of_lower_angle():
    """A prosthetic finger link (427 vertices, a face with a 3e-6 deg corner): the rounds
    leave 14 folds; the descent from the central projection stalls at 3.95 times a conformal
    map's distortion (6.5 deg), the one from the Tutte map converges (1.36 times, 10.9 deg).
    The stalled map is no minimizer: returning it made the result a failure (exit 3) although
    a converged fold-free map was at hand."""
    V, F = load_mesh("mpl_pinky0_left.obj")
    r = _quiet(V, F)
    assert r.success and r.converged and r.folds == 0
    assert count_folds(r.F, r.U) == 0 and abs(map_degree(r.F, r.U) - 1.0) < 1e-6

def _distorted_share(V, F, U, above):
    """Share of the input's area on faces whose half MIPS energy (Hormann, Greiner 2000) of the
    linear map onto the chordal image triangle, ``|J|_F^2 / (2 det J)``, is above ``above``: a
    lower bound of the share the polish rule counts (its denominators are at most the image
    areas)."""
    area = igl.doublearea(V, F)

    def edges_in_frame(X):  # (m, 2, 2): the two edges at corner 0 in the triangle's plane
        e1, e2 = X[F[:, 1]] - X[F[:, 0]], X[F[:, 2]] - X[F[:, 0]]
        x = e1 / np.linalg.norm(e1, axis=1, keepdims=True)
        n = np.cross(e1, e2)
        y = np.cross(n / np.linalg.norm(n, axis=1, keepdims=True), x)
        return np.stack([np.stack([(e * x).sum(1), (e * y).sum(1)], 1) for e in (e1, e2)], 2)

    J = edges_in_frame(U) @ np.linalg.inv(edges_in_frame(V))
    half_mips = (J ** 2).sum(axis=(1, 2)) / (2.0 * np.linalg.det(J))
    return float(area[half_mips > above].sum() / area.sum())


def test_an_accepted_map_far_from_conformal_is_polished(monkeypatch):
    """Round 0's map stretched 12:1 across the ellipsoid's axis (a linear map of the sphere,
    projected back: every face keeps its orientation, nothing frozen), so the verdict accepts
    it while more than a tenth of its area is on faces more than twice as distorted as a
    conformal map's.  The default descends from it (a "polish" round that says why) and
    returns a map with a lower angle distortion; ``polish="never"`` returns the stretched map."""
    import igl_spheremap.folding.problem as problem
    from igl_spheremap.folding.guaranteed import POLISH_DISTORTION, POLISH_SHARE

    V, F = ellipsoid(3.0)
    real, calls = problem.minimize, []

    def stretched_first(*args, **kw):
        res = real(*args, **kw)
        if not calls:
            U = res.U * np.array([12.0, 1.0, 1.0])
            res.U = U / np.linalg.norm(U, axis=1, keepdims=True)
        calls.append(1)
        return res

    monkeypatch.setattr(problem, "minimize", stretched_first)
    plain = _quiet(V, F, polish="never")
    calls.clear()
    r = _quiet(V, F)
    assert [x.kind for x in plain.rounds] == ["gauss"] and plain.rounds[0].frozen == 0
    assert plain.folds == 0 and count_folds(plain.F, plain.U) == 0
    assert _distorted_share(V, F, plain.U, POLISH_DISTORTION) > POLISH_SHARE
    assert [x.kind for x in r.rounds] == ["gauss", "polish"]
    assert "times a conformal map's distortion" in r.message
    before = igl_spheremap.angle_distortion(V, F, plain.U).mean()
    after = igl_spheremap.angle_distortion(V, F, r.U).mean()
    assert after < 0.5 * before and _distorted_share(V, F, r.U, POLISH_DISTORTION) < 0.01
    assert r.success and count_folds(r.F, r.U) == 0


# ------------------------------------------------------------------------- centering

def test_a_centering_that_folds_is_not_kept(icosphere, monkeypatch):
    import igl_spheremap.folding.centering as centering

    V, F = icosphere(3)
    V = V * np.array([1.0, 1.2, 0.8])
    monkeypatch.setattr(centering, "mobius_center", lambda U, w: (-U, 0.0))  # every face flips
    r = _quiet(V, F)
    assert np.array_equal(r.U, r.rounds[-1].U) and r.folds == 0


def test_a_centering_that_folds_a_few_faces_gets_kernel_moves(icosphere, monkeypatch):
    import igl_spheremap.folding.centering as centering

    V, F = icosphere(3)
    V = V * np.array([1.0, 1.2, 0.8])
    real = centering.mobius_center
    monkeypatch.setattr(centering, "mobius_center",
                        lambda U, w: (drag_past_neighbor(F, real(U, w)[0], 50, 1.6), 0.0))
    r = _quiet(V, F)
    assert r.folds == 0 and not np.array_equal(r.U, r.rounds[-1].U)


def test_a_map_that_folds_already_gets_no_kernel_moves_at_its_centering(icosphere, monkeypatch):
    """The kernel moves keep a fold-free map fold-free; on a map Algorithm 2 left folded (a
    collapse, which the guaranteed path replaces) the centering is kept only if it folds no more
    faces, and nothing is untangled."""
    import igl_spheremap.folding.centering as centering

    V, F = icosphere(3)
    problem = map_problem(V * np.array([1.0, 1.2, 0.8]), F)
    mesh = problem.mesh
    U = drag_past_neighbor(mesh.F, V, 10, 1.6)  # central projection with one vertex dragged
    folds = count_folds(mesh.F, U)
    monkeypatch.setattr(centering, "mobius_center",
                        lambda X, w: (drag_past_neighbor(mesh.F, X, 200, 1.6), 0.0))
    untangled, real = [], centering.untangle_folds
    monkeypatch.setattr(centering, "untangle_folds",
                        lambda *a, **k: untangled.append(a) or real(*a, **k))
    out, left = centering.final_centering(problem, mesh.to_input(U), folds)
    assert folds > 0 and untangled == []
    assert np.array_equal(out, U) and left == folds
    out, left = centering.final_centering(problem, mesh.to_input(V), 0)  # fold-free: moves
    assert len(untangled) == 1 and left == 0


# ------------------------------------------------------------------------- float32 repairs

def _record_repairs(monkeypatch):
    from igl_spheremap.precision import repair

    tried = []
    for name in list(repair.REPAIRS):
        monkeypatch.setitem(repair.REPAIRS, name,
                            lambda *a, name=name: tried.append(name) or "skipped by the test")
    return tried


@pytest.mark.parametrize("mesh, first", [
    (lambda: ellipsoid(30.0), "compressed metric"),    # round 0 under the barrier
    (lambda: capsule(50.0), "central projection"),     # star-shaped, Gauss map folds
    (lambda: load_mesh("dino.obj"), "cluster inflation"),
])
def test_float32_repairs_are_tried_in_the_order_of_the_cause(monkeypatch, mesh, first):
    tried = _record_repairs(monkeypatch)
    V, F = mesh()
    r = _quiet(V, F, precision="float32", guaranteed_path=False)
    assert r.repair is not None and r.repair["below_before"] > 0
    assert tried[0] == first and len(tried) == 3
    assert [t["method"] for t in r.repair["tried"]] == tried
    assert not r.success and r.below_margin > 0


def test_float64_runs_no_repair():
    V, F = ellipsoid(30.0)
    assert _quiet(V, F).repair is None


# ------------------------------------------------------------------------- the result

def test_a_barrier_that_froze_most_vertices_is_no_success():
    V, F = ellipsoid(1000.0)
    r = _quiet(V, F, guaranteed_path=False)
    assert r.folds == 0 and "far from conformal" in r.message and not r.success
    assert igl_spheremap.map_degree(r.F, r.U) == pytest.approx(1.0, abs=1e-9)

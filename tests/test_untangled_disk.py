"""The punctured Tutte disk untangled in the plane (folding/untangled_disk.py): the regularized
energy against finite differences, the update of eps, untangling a folded disk, and the
start the guaranteed path takes where rounding broke every Tutte embedding."""

import igl
import numpy as np
import pytest

from igl_spheremap.folding import untangled_disk as ud
from igl_spheremap.folding import guaranteed
from igl_spheremap.folding.guaranteed import (candidate_rounds, conformal_descent, quality,
                                              start_groups)
from igl_spheremap.folding.starts import central_projection
from igl_spheremap.folding.tutte_start import TUTTE_WEIGHTS, tutte_sphere_map
from igl_spheremap.mesh.shapes import capsule, icosphere
from igl_spheremap.mesh.validate import validate_mesh
from igl_spheremap.sphere.chart import planar_signed_areas
from igl_spheremap.sphere.folds import below_margin, count_folds, map_degree

from conftest import load_mesh, map_problem


@pytest.fixture(scope="module")
def grid():
    """A 6 x 6 planar grid (flat input), its boundary fixed, an interior vertex pushed
    across its neighbours so that some faces are folded."""
    x, y = np.meshgrid(np.linspace(0, 1, 6), np.linspace(0, 1, 6))
    V = np.column_stack([x.ravel(), y.ravel(), np.zeros(36)])
    F = []
    for i in range(5):
        for j in range(5):
            a, b, c, d = 6 * i + j, 6 * i + j + 1, 6 * (i + 1) + j, 6 * (i + 1) + j + 1
            F += [[a, b, d], [a, d, c]]
    F = np.array(F, dtype=np.int64)
    fixed = np.zeros(36, dtype=bool)
    fixed[np.asarray(igl.boundary_loop(F))] = True
    X = V[:, :2].copy()
    X[14] += (0.45, 0.3)
    return V, F, X, fixed


def test_gradient_matches_finite_differences(grid):
    V, F, X, _ = grid
    E = ud.UntanglingEnergy(V, F, 1.0)
    D = np.random.default_rng(0).standard_normal(X.shape)
    h, eps = 1e-6, 0.1
    fd = (E.value(X + h * D, eps)[0] - E.value(X - h * D, eps)[0]) / (2 * h)
    assert np.vdot(E.gradient(X, eps), D) == pytest.approx(fd, rel=1e-6)


def test_hessian_matches_finite_differences_of_the_gradient(grid, monkeypatch):
    """Without the projection the assembled Hessian is the derivative of the gradient;
    with it, positive semidefinite."""
    V, F, X, _ = grid
    E, eps = ud.UntanglingEnergy(V, F, 1.0), 0.1
    D = np.random.default_rng(1).standard_normal(X.shape)
    H = E.hessian(X, eps)
    assert np.linalg.eigvalsh(H.toarray()).min() >= -1e-9 * abs(H).max()
    real = ud.invariant_hessians
    monkeypatch.setattr(ud, "invariant_hessians", lambda *a: real(*a, project=False))
    h = 1e-6
    fd = (E.gradient(X + h * D, eps) - E.gradient(X - h * D, eps)) / (2 * h)
    np.testing.assert_allclose(E.hessian(X, eps) @ D.ravel(), fd.ravel(), rtol=1e-5,
                               atol=1e-6 * np.abs(fd).max())


def test_energy_is_its_minimum_on_an_area_preserving_similarity(grid):
    """At ``J = I`` every face's term is ``A_f (1 + 1) / 2 / 1``: the energy is the total area."""
    V, F, _, _ = grid
    E = ud.UntanglingEnergy(V, F, 1.0)
    value, d = E.value(V[:, :2], 0.0)
    assert value == pytest.approx(1.0) and np.allclose(d, 1.0)


def test_equilateral_reference_triangles_have_rotations_as_jacobians():
    """Without the input's triangles, the reference is equilateral of area ``total / m``:
    an equilateral layout of that area has rotations as Jacobians (``J^T J = I``, ``det J =
    1``) and the energy is the total area, whatever the layout's orientation."""
    total, theta = 3.0, 0.7
    side = np.sqrt(4.0 * (total / 2) / np.sqrt(3.0))
    tri = side * np.array([[0.0, 0.0], [1.0, 0.0], [0.5, np.sqrt(3.0) / 2]])
    R = np.array([[np.cos(theta), -np.sin(theta)], [np.sin(theta), np.cos(theta)]])
    X = np.vstack([tri, tri + [5.0, 0.0]]) @ R.T
    F = np.array([[0, 1, 2], [3, 4, 5]], dtype=np.int64)
    E = ud.UntanglingEnergy(6, F, total)
    J = E.jacobians(X)
    np.testing.assert_allclose(J.transpose(0, 2, 1) @ J, np.broadcast_to(np.eye(2), (2, 2, 2)),
                               atol=1e-12)
    value, d = E.value(X, 0.0)
    assert value == pytest.approx(total) and np.allclose(d, 1.0)


def test_next_eps_follows_the_rule():
    """``dmin >= mu`` ends the regularization; at ``dmin = 0`` and no decrease of the energy,
    ``eps`` falls by ``SIGMA_MIN`` exactly (``mu = (1 - sigma) eps / 2``)."""
    assert ud.next_eps(0.1, 2.0, 1.0, 0.5) == 0.0
    assert ud.next_eps(0.1, 1.0, 1.0, 0.0) == pytest.approx((1 - ud.SIGMA_MIN) * 0.1)
    mu = 0.5 * ud.chi(-0.2, 0.3)[0]
    assert ud.next_eps(0.3, 2.0, 1.0, -0.2) == pytest.approx(2 * np.sqrt(mu * (mu + 0.2)))


def test_a_folded_disk_is_untangled_with_its_boundary_kept(grid):
    V, F, X, fixed = grid
    assert np.count_nonzero(planar_signed_areas(X, F) <= 0) > 0
    Y, info = ud.untangle_disk(V, F, X, fixed)
    assert np.all(planar_signed_areas(Y, F) > 0) and info["min_det"] > 0
    np.testing.assert_array_equal(Y[fixed], X[fixed])
    Y, info = ud.untangle_disk(None, F, X, fixed)  # toward equilateral triangles
    assert np.all(planar_signed_areas(Y, F) > 0) and info["min_det"] > 0
    np.testing.assert_array_equal(Y[fixed], X[fixed])


def test_where_every_tutte_embedding_folds_the_untangled_start_does_not():
    """A 50:1 capsule: its punctured Tutte embeddings crowd below float64 along the tube."""
    mesh = validate_mesh(*capsule(50.0, n_around=8))
    V, F = mesh.V, mesh.F
    assert all(count_folds(F, tutte_sphere_map(V, F, w)[0]) > 0 for w in TUTTE_WEIGHTS)
    U, info = ud.untangled_sphere_map(V, F)
    assert count_folds(F, U) == 0 and info["min_det"] > 0
    assert map_degree(F, U) == pytest.approx(1.0)


def tutte_starts(problem):
    """The Tutte and untangled starts of the guaranteed path without a rounds' map, in order."""
    return [(kind, U) for group in start_groups(problem) for kind, U in group
            if kind in ("tutte", "untangled")]


def test_the_guaranteed_path_untangles_only_where_rounding_broke_the_tutte_start():
    """A 20:1 capsule: every Tutte embedding is fold-free in float64 but has faces below the
    float32 rounding margin; in float32 the guaranteed path offers the untangled disk first,
    then the first fold-free embedding."""
    V, F = capsule(20.0)
    assert [kind for kind, _ in tutte_starts(map_problem(V, F, "float64"))] == ["tutte"]
    problem = map_problem(V, F, "float32")
    assert all(below_margin(problem.F, tutte_sphere_map(problem.mesh.V, problem.F, w)[0]).any()
               for w in TUTTE_WEIGHTS)
    starts = tutte_starts(problem)
    assert [kind for kind, _ in starts] == ["untangled", "tutte"]
    U = starts[0][1]
    assert count_folds(problem.F, U) == 0 and not below_margin(problem.F, U, "float32").any()


def test_the_untangled_disk_waits_for_the_descent_from_the_rounds_map(monkeypatch):
    """A 20:1 capsule in float32, every Tutte embedding below the margin: given a rounds' map
    that can start a descent (here its central projection, fold-free and above the margin),
    the descent from it gives a valid, converged map and the untangled disk is never built.
    With no such map the untangled disk is built, scored beside the first fold-free Tutte
    map, and a descent from one of them gives the map."""
    V, F = capsule(20.0)
    problem = map_problem(V, F, "float32")
    U = central_projection(problem.mesh.V, problem.F)
    assert count_folds(problem.F, U) == 0 and not below_margin(problem.F, U, "float32").any()
    built = []
    untangle = ud.untangled_sphere_map
    monkeypatch.setattr(guaranteed, "untangled_sphere_map",
                        lambda V, F: built.append(1) or untangle(V, F))
    monkeypatch.setattr(guaranteed, "central_projection", lambda V, F: None)
    rounds = candidate_rounds(problem, 0, rounds_map=U)
    assert [r.kind for r in rounds] == ["polish"] and not built
    assert rounds[0].run.converged and quality(problem, problem.mesh.from_input(rounds[0].U))[0]
    rounds = candidate_rounds(problem, 0)
    assert built and {r.kind for r in rounds} <= {"untangled", "tutte"}
    assert rounds[-1].run.converged and quality(problem, problem.mesh.from_input(rounds[-1].U))[0]


def test_the_tutte_start_passed_over_for_the_float32_margin_is_the_last_resort():
    """A prosthetic finger link (427 vertices): its cotangent Tutte map is fold-free with faces
    below the float32 rounding margin, so in float32 the guaranteed path starts from the
    uniform one; the cotangent map is kept for when every start fails, and its descent lifts
    every face above the margin (the energy does not guard them, nothing holds them down).
    In float64 nothing is passed over."""
    V, F = load_mesh("mpl_pinky0_left.obj")
    problem = map_problem(V, F, "float32")
    Vm, Fm = problem.mesh.V, problem.F
    maps = {w: tutte_sphere_map(Vm, Fm, w)[0] for w in TUTTE_WEIGHTS}
    assert all(count_folds(Fm, U) == 0 for U in maps.values())
    assert below_margin(Fm, maps["cotan_positive"], "float32").sum() > 0
    assert not below_margin(Fm, maps["uniform"], "float32").any()
    groups = list(start_groups(problem))
    tutte = [U for kind, U in groups[0] if kind == "tutte"]
    assert len(tutte) == 1 and np.array_equal(tutte[0], maps["uniform"])
    assert len(groups) == 2 and len(groups[1]) == 1  # the last resort, alone
    kind, U0 = groups[1][0]
    assert kind == "tutte" and np.array_equal(U0, maps["cotan_positive"])
    run = conformal_descent(problem, U0, 0)
    assert run.converged and count_folds(Fm, run.U) == 0
    assert not below_margin(Fm, run.U, "float32").any()
    assert abs(map_degree(Fm, run.U) - 1.0) < 1e-6
    assert list(start_groups(map_problem(V, F, "float64")))[1:] == [[]]


def needle_icosphere():
    """An icosphere turned off the axes (whose zeros float32 keeps exact) with one edge split
    1e-8 of its length from an end: two needle faces, fold-free under central projection with
    their images below the float32 rounding margin."""
    V, F = icosphere(2)
    V = V @ np.linalg.qr(np.array([[1.0, 2.0, 3.0], [0.0, 1.0, 4.0], [5.0, 6.0, 0.0]]))[0]
    a, b = F[0, 0], F[0, 1]
    m = V.shape[0]
    V = np.vstack([V, V[a] + 1e-8 * (V[b] - V[a])])
    split = [(a in f) and (b in f) for f in F]
    F = np.vstack([F[~np.array(split)]]
                  + [np.array([[m if x == b else x for x in f], [m if x == a else x for x in f]])
                     for f, s in zip(F, split) if s])
    return V, F


def test_a_fold_free_map_is_judged_with_its_input_slivers_lifted_above_the_margin():
    """An icosphere with one edge split 1e-8 of its length from an end (two needle faces):
    its central projection is fold-free with the needles' images below the float32 rounding
    margin, so stored in float32 at radius 100 they degenerate.  :func:`quality` (which judges
    the guaranteed path's descents, also the one from a start passed over for such faces)
    lifts them: valid, and the stored map keeps every face positive."""
    V, F = needle_icosphere()
    problem = map_problem(V, F, "float32")
    Fm = problem.F
    U = problem.mesh.V / np.linalg.norm(problem.mesh.V, axis=1, keepdims=True)
    assert count_folds(Fm, U) == 0 and below_margin(Fm, U, "float32").sum() == 2

    def stored_folds(X):
        Y = (100.0 * X).astype(np.float32).astype(np.float64)
        return int((np.einsum("ij,ij->i", Y[Fm[:, 0]], np.cross(Y[Fm[:, 1]], Y[Fm[:, 2]]))
                    <= 0).sum())

    assert stored_folds(U) > 0
    ok, angle, X = quality(problem, U)
    assert ok and count_folds(Fm, X) == 0 and not below_margin(Fm, X, "float32").any()
    assert stored_folds(X) == 0
    assert angle < 1.0  # degrees; the central projection of an icosphere is nearly conformal


def test_a_map_from_the_untangled_start_says_why_it_is_far_from_conformal(monkeypatch):
    """The 50:1 capsule with the rounds' map rejected and no central start: the map comes from
    the untangled disk, fold-free, and its message says that it gave up angle for area."""
    import warnings

    from igl_spheremap import spherical_conformal_map
    from igl_spheremap.folding import guaranteed

    monkeypatch.setattr(guaranteed, "verdict", lambda *a: (False, "rejected by the test"))
    monkeypatch.setattr(guaranteed, "central_projection", lambda V, F: None)
    V, F = capsule(50.0, n_around=8)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = spherical_conformal_map(V, F)
    assert r.folds == 0 and count_folds(r.F, r.U) == 0 and r.success
    assert "untangled start" in r.message and "gave up angle for area" in r.message


def test_a_rounds_map_rejected_for_input_slivers_is_offered_lifted_as_a_start(monkeypatch):
    """The needle icosphere's central projection as the rounds' map in float32: rejected for
    the two needles below the margin, it is still offered to the guaranteed path as its
    ``"polish"`` start, with the needles lifted (before, it was dropped, and only starts far
    from conformal were left); where the barrier held the round, its initial map is offered,
    lifted the same way."""
    from types import SimpleNamespace

    from igl_spheremap.folding import guaranteed

    V, F = needle_icosphere()
    problem = map_problem(V, F, "float32")
    Fm = problem.F
    U = problem.mesh.V / np.linalg.norm(problem.mesh.V, axis=1, keepdims=True)
    c, s = np.cos(0.3), np.sin(0.3)
    turned = U @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])  # the needles below too
    offered = []
    monkeypatch.setattr(guaranteed, "candidate_rounds",
                        lambda problem, index, previous=None, rounds_map=None:
                        offered.append(rounds_map) or [])
    n = U.shape[0]
    for frozen, expected in ((0, U), (n, turned)):
        chosen = SimpleNamespace(frozen=frozen, U_init=problem.mesh.to_input(turned), kind="star")
        ok, why = guaranteed.verdict(problem, U, chosen, 0)
        assert not ok and "2 faces below" in why
        guaranteed.guaranteed_map(problem, [chosen], U, chosen, 0)
        start = offered[-1]
        assert start is not None and count_folds(Fm, start) == 0
        assert not below_margin(Fm, start, "float32").any()
        assert np.abs(start - expected).max() < 1e-6

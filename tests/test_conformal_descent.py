"""The conformal descent of the guaranteed path: the conformal-distortion energy, the per-face
maximal step along the Cayley curve, and Algorithm 1 under a fold barrier that never freezes."""

import numpy as np
import pytest

from igl_spheremap.folding.starts import central_projection
from igl_spheremap.mesh.operators import SPHERE_AREA, signed_volumes, to_sphere_area, vertex_areas
from igl_spheremap.mesh.shapes import icosphere, split_icosphere
from igl_spheremap.mesh.validate import validate_mesh
from igl_spheremap.optimize.conformal_distortion import ConformalDistortionEnergy
from igl_spheremap.optimize.feasible_step import (max_step, max_steps, moved_faces, poly_eval,
                                                  smallest_step, volume_polynomials)
from igl_spheremap.optimize.manifold import cayley_step
from igl_spheremap.optimize.minimize import minimize
from igl_spheremap.options import map_options
from igl_spheremap.sphere.folds import count_folds
from igl_spheremap.sphere.quality import angle_distortion


def _energy(V, F):
    return ConformalDistortionEnergy(V, F, to_sphere_area(vertex_areas(V, F)))


def _tangent(U, X):
    return X - np.sum(U * X, axis=1)[:, None] * U


def test_energy_gradient_matches_finite_differences(stretched):
    V, F, U = stretched
    E = _energy(V, F)
    g = E.euclidean_gradient(E.evaluate(U))
    D = np.random.default_rng(1).standard_normal(U.shape)
    h = 1e-6
    fd = (E.value(U + h * D) - E.value(U - h * D)) / (2 * h)
    assert np.vdot(g, D) == pytest.approx(fd, rel=1e-6)


def test_auto_solver_of_the_newton_metric_counts_vertices(stretched, monkeypatch):
    """``h1_solver="auto"`` draws the line at AUTO_DIRECT_MAX_SIZE vertices, not 2 n unknowns."""
    from igl_spheremap.optimize import preconditioner
    V, F, _ = stretched
    monkeypatch.setattr(preconditioner, "AUTO_DIRECT_MAX_SIZE", V.shape[0])
    assert _energy(V, F).metric.solver == "direct"
    monkeypatch.setattr(preconditioner, "AUTO_DIRECT_MAX_SIZE", V.shape[0] - 1)
    assert _energy(V, F).metric.solver == "amg"


def test_energy_is_4pi_for_a_similar_image_and_more_otherwise(stretched):
    """The identity of a fine sphere mesh is conformal up to the chordal O(h^2); the energy
    of every map is at least 4 pi (each term at least its face's area)."""
    V, F = icosphere(4)
    assert _energy(V, F).value(V) / SPHERE_AREA == pytest.approx(1.0, abs=2e-3)
    V, F, U = stretched
    assert _energy(V, F).value(U) > SPHERE_AREA


def test_energy_is_infinite_on_a_folded_face(stretched):
    V, F, U = stretched
    i, j, k = F[0]
    Y = U.copy()
    Y[i] = Y[j] + (Y[j] - Y[i])  # across the opposite edge's line
    Y /= np.linalg.norm(Y, axis=1, keepdims=True)
    assert signed_volumes(F[:1], Y)[0] <= 0
    assert _energy(V, F).value(Y) == np.inf


def test_face_distortion_of_an_inscribed_mesh_is_the_inverse_plane_distance(stretched):
    """A mesh inscribed in the unit sphere mapped to itself: each face is similar to its image,
    so its term over its area is ``1 / d_f``, ``d_f`` the distance of its plane from the
    centre (numpy); the terms times the input areas sum to the energy; a folded face's is
    infinite."""
    V, F = icosphere(2)
    E = _energy(V, F)
    n = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    d = np.sum(n / np.linalg.norm(n, axis=1, keepdims=True) * V[F[:, 0]], axis=1)
    assert np.allclose(E.face_distortion(V), 1.0 / d, rtol=1e-12)
    V, F, U = stretched
    E = _energy(V, F)
    assert np.sum(E.face_area * E.face_distortion(U)) == pytest.approx(E.value(U), rel=1e-12)
    assert E.face_area.sum() == pytest.approx(SPHERE_AREA, rel=1e-12)
    Y = U.copy()
    i, j, _ = F[0]
    Y[i] = Y[j] + (Y[j] - Y[i])
    Y /= np.linalg.norm(Y, axis=1, keepdims=True)
    assert E.face_distortion(Y)[0] == np.inf


def test_energy_does_not_depend_on_the_mesh_scale(stretched):
    V, F, U = stretched
    assert _energy(1e3 * V, F).value(U) == pytest.approx(_energy(V, F).value(U), rel=1e-12)


@pytest.fixture(scope="module")
def curve():
    V, F = icosphere(2)
    U = V / np.linalg.norm(V, axis=1, keepdims=True)
    X = _tangent(U, np.random.default_rng(2).standard_normal(U.shape))
    return F, U, X


def test_volume_polynomial_is_the_signed_volume_along_the_cayley_curve(curve):
    F, U, X = curve
    Q = volume_polynomials(F, U, X)
    c = 0.25 * np.sum(X * X, axis=1)
    for tau in (0.1, 0.5, 2.0):
        d = np.prod(1.0 + c[F] * tau ** 2, axis=1)
        s = signed_volumes(F, cayley_step(U, X, tau, tangent=True))
        assert np.abs(poly_eval(Q, tau) / d - s).max() < 1e-14


@pytest.mark.parametrize("share", [0.5, 0.0])
def test_max_steps_is_a_lower_bound_within_2_percent_of_the_first_root(curve, share):
    """Against the signed volumes of the Cayley points themselves (threshold half the start's
    volume, or 0: the fold itself): at or above the threshold up to the step, below it 2%
    after."""
    F, U, X = curve
    s0 = signed_volumes(F, U)
    t = share * s0
    taus = max_steps(volume_polynomials(F, U, X, t), 10.0)
    grid = np.linspace(0.0, 1.0, 201)
    for f in np.argsort(taus)[:20]:  # the limiting faces: no crossing before, one just after
        s = [signed_volumes(F[f:f + 1], cayley_step(U, X, g * taus[f], tangent=True))[0]
             for g in grid]
        assert min(s) >= t[f] * (1 - 1e-9) and (share or min(s) > 0)
        after = signed_volumes(F[f:f + 1], cayley_step(U, X, taus[f] * 1.02, tangent=True))[0]
        assert after < t[f]
    assert smallest_step(volume_polynomials(F, U, X, t), 10.0) == pytest.approx(taus.min())


def test_faces_not_flagged_as_moved_cannot_reach_their_threshold(curve):
    F, U, X = curve
    s0 = signed_volumes(F, U)
    tau = 0.02
    flagged = moved_faces(F, U, X, tau, 0.5 * s0)
    assert 0 < flagged.sum() < F.shape[0]
    for g in np.linspace(0.0, tau, 11):
        s = signed_volumes(F, cayley_step(U, X, g, tangent=True))
        assert np.all(s[~flagged] > 0.5 * s0[~flagged])
    assert max_step(F, U, X, tau, s0, 0.5 * s0) == pytest.approx(
        min(tau, max_steps(volume_polynomials(F, U, X, 0.5 * s0), tau).min()))


def test_a_tiny_face_keeps_an_accurate_polynomial():
    """A face with edges of 1e-7: the coefficients come from edge differences, so the
    polynomial's value at 0 is its signed volume to full relative precision."""
    P = np.array([[0.0, 0.0, 1.0], [1e-7, 0.0, 1.0], [0.0, 1e-7, 1.0], [0.6, 0.8, 0.0]])
    U = P / np.linalg.norm(P, axis=1, keepdims=True)
    F = np.array([[0, 1, 2]])
    X = _tangent(U, np.ones_like(U))
    Q = volume_polynomials(F, U, X)
    assert Q[0, 0] == pytest.approx(signed_volumes(F, U)[0], rel=1e-9)
    assert Q[0, 0] == pytest.approx(1e-14, rel=1e-6)


def test_the_descent_never_freezes_and_stays_fold_free():
    """From the central projection of the split icosphere (fold-free, 2,562 vertices, most
    of them frozen by the freezing barrier from the Gauss map): converged, nothing frozen."""
    mesh = validate_mesh(*split_icosphere(3))
    V, F = mesh.V, mesh.F
    E = _energy(V, F)
    folds = []
    r = minimize(E, central_projection(V, F), F, map_options(gtol=1e-3), fold_barrier=True,
                 feasible=True, callback=lambda k, U, e, g: folds.append(count_folds(F, U)))
    assert r.converged and r.frozen == 0 and r.folds == 0 and not any(folds)
    assert r.energy / SPHERE_AREA < 1.01
    reference = angle_distortion(V, F, central_projection(V, F)).mean()  # 0.086 degrees
    assert angle_distortion(V, F, r.U).mean() < 1.5 * reference


# ------------------------------------------------------------------------- polish

def test_polish_lowers_the_angle_distortion_of_an_accepted_map():
    """The fish's Gauss-map round is accepted; with ``polish="always"`` the conformal descent runs
    from it and its map, fold-free, has the lower mean angle distortion (libigl's angles)."""
    from igl_spheremap import spherical_conformal_map
    from conftest import load_mesh

    V, F = load_mesh("fish_lowres.obj")
    plain = spherical_conformal_map(V, F)
    polished = spherical_conformal_map(V, F, polish="always")
    assert [r.kind for r in plain.rounds] == ["gauss"]
    assert [r.kind for r in polished.rounds] == ["gauss", "polish"]
    assert polished.success and polished.folds == 0 == count_folds(polished.F, polished.U)
    before = angle_distortion(V, F, plain.U).mean()
    after = angle_distortion(V, F, polished.U).mean()
    assert after < before - 0.05  # degrees
    assert f"{before:.2f} -> {after:.2f} deg" in polished.message


def test_a_polish_that_loses_says_what_its_descent_gave():
    """The goat head's Gauss-map round is accepted; with ``polish="always"`` the conformal
    descent converges to a map of higher mean angle distortion, so the rounds' map is
    returned, and the message gives both angles (the returned map's as libigl's angles
    measure it), not "did not lower ... or did not converge"."""
    import re
    from igl_spheremap import spherical_conformal_map
    from conftest import load_mesh

    V, F = load_mesh("goathead.obj")
    r = spherical_conformal_map(V, F, polish="always")
    assert [x.kind for x in r.rounds] == ["gauss", "polish"] and r.rounds[-1].run.converged
    found = re.search(r"the conformal descent converged at ([0-9.]+) deg mean angle distortion, "
                      r"no lower; the rounds' map kept \(([0-9.]+) deg", r.message)
    assert found, r.message
    descent, kept = map(float, found.groups())
    assert descent > kept
    assert abs(angle_distortion(V, F, r.U).mean() - kept) < 0.006  # printed to 2 decimals
    assert r.success and r.folds == 0 == count_folds(r.F, r.U)


def test_every_step_of_the_polish_lowers_its_energy():
    """The conformal descent searches monotonically (``xi = 0``): the energy of every accepted
    iterate of the fish's and the dino's polish is below the one before it, and each run
    converged.  (With the paper's nonmonotone ``xi = 0.85`` both accepted increases.)"""
    from igl_spheremap import spherical_conformal_map
    from conftest import load_mesh

    for name, kw in (("fish_lowres.obj", dict(polish="always")), ("dino.obj", {})):
        V, F = load_mesh(name)
        run = spherical_conformal_map(V, F, **kw).rounds[-1]
        assert run.kind == "polish" and run.run.converged
        history = np.asarray(run.run.energy_history)
        assert history.size > 5 and np.all(np.diff(history) < 0), name


def test_a_partly_held_map_is_polished_keeping_the_float32_margin():
    """dino in float32: the star round's barrier holds more than a tenth of the vertices and the
    repaired map is above the margin; the default descends from it (with ``polish="never"``
    it is returned as repaired), stays above the margin, so fold-free once stored, and has a
    lower angle distortion."""
    import warnings

    from igl_spheremap import SphericalMapWarning, spherical_conformal_map
    from igl_spheremap.sphere.folds import below_margin
    from conftest import load_mesh

    V, F = load_mesh("dino.obj")
    with warnings.catch_warnings():
        warnings.simplefilter("error", SphericalMapWarning)
        plain = spherical_conformal_map(V, F, precision="float32", polish="never")
        polished = spherical_conformal_map(V, F, precision="float32")
    assert plain.repair is not None and [r.kind for r in plain.rounds] == ["gauss", "star"]
    assert plain.rounds[1].frozen > 0.1 * len(V)
    assert polished.rounds[-1].kind == "polish" and "frozen" in polished.message
    assert polished.success and not below_margin(polished.F, polished.U, "float32").any()
    assert count_folds(F, polished.U.astype(np.float32).astype(np.float64)) == 0
    assert angle_distortion(V, F, polished.U).mean() < angle_distortion(V, F, plain.U).mean() - 1.0


def test_a_round_from_untangled_patches_is_polished():
    """The Unitree G1 elbow link: no Tutte patch or kernel move removes the star map's folds,
    the untangled patches do, and Algorithm 1 from there converges fold-free with little
    held, in the patches' basin.  The default
    descends from that map (with ``polish="never"`` it is returned as it is) and lowers the
    mean angle distortion (libigl's angles) by more than a degree."""
    from igl_spheremap import spherical_conformal_map
    from conftest import load_mesh

    V, F = load_mesh("g1_right_elbow_link.obj")
    plain = spherical_conformal_map(V, F, polish="never")
    polished = spherical_conformal_map(V, F)
    assert [r.kind for r in plain.rounds] == ["gauss", "star"] and plain.success
    star = plain.rounds[1]
    assert star.patched and star.folds_star > 0 and star.folds_before == 0
    assert star.frozen < 0.1 * len(V)
    assert polished.rounds[-1].kind == "polish" and "untangled patches" in polished.message
    assert polished.success and polished.folds == 0 == count_folds(polished.F, polished.U)
    assert angle_distortion(V, F, polished.U).mean() < angle_distortion(V, F, plain.U).mean() - 1.0


def test_a_held_round_is_polished_from_its_own_start_where_that_can_start():
    """``held_start``: where the barrier froze more than ``POLISH_SHARE`` of the vertices, the
    descent starts from the round's initial map, if that map is fold-free and of degree 1;
    otherwise, and where the barrier held few vertices, from the rounds' map itself."""
    from types import SimpleNamespace

    from conftest import load_mesh
    from igl_spheremap import spherical_conformal_map
    from igl_spheremap.folding.guaranteed import POLISH_SHARE, held_start
    from igl_spheremap.folding.problem import MapProblem

    V, F = load_mesh("fish_lowres.obj")
    problem = MapProblem.of(validate_mesh(V, F), map_options())
    U = spherical_conformal_map(V, F).U  # fold-free, degree 1 (the fish has no unused vertex)
    c, s = np.cos(0.3), np.sin(0.3)
    turned = U @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])  # fold-free, degree 1
    mirrored = U * np.array([-1.0, 1.0, 1.0])  # every face folded: degree -1
    assert count_folds(F, U) == count_folds(F, turned) == 0
    assert np.all(signed_volumes(F, mirrored) < 0)
    n, held = len(V), int(POLISH_SHARE * len(V)) + 1

    start, source = held_start(problem, U, SimpleNamespace(frozen=held, U_init=turned, kind="star"))
    assert np.array_equal(start, turned) and "star round" in source
    start, _ = held_start(problem, U, SimpleNamespace(frozen=held - 1, U_init=turned, kind="star"))
    assert start is U  # few vertices held: the map itself
    start, _ = held_start(problem, U, SimpleNamespace(frozen=n, U_init=mirrored, kind="star"))
    assert start is U  # a start that cannot start the descent is passed over

"""igl_spheremap.optimize.minimize: paper Algorithm 1 end to end (gradient, critical points, stopping,
barrier); its pieces are tested in test_energies, test_step_size, test_line_search,
test_constraints, test_gauge and test_search_direction."""

import itertools
import time

import igl
import numpy as np
import pytest

from igl_spheremap import (
    count_folds,
    folded_faces,
    gauss_map,
    harmonic_energy,
    harmonic_map,
    mobius_center,
    star_map,
)
from igl_spheremap.optimize.manifold import cayley_step
from igl_spheremap.mesh.operators import vertex_areas

# Algorithm 1 as published.
PAPER = {"laplacian_kind": "cotan", "metric": "L2", "mobius": False}


def _unit(X):
    return X / np.linalg.norm(X, axis=1, keepdims=True)


def _rowdot(X, Y):
    return np.einsum("ij,ij->i", X, Y)


def _areas(V, F):
    """Barycentric vertex areas of the mesh scaled to total area 4 pi (libigl mass matrix)."""
    A = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_BARYCENTRIC).diagonal()
    return A * (4.0 * np.pi / A.sum())


def _riemannian_gradient(V, F, U):
    """G = tangential part of H = -M^{-1} L U with igl.cotmatrix (paper H = -Delta F)."""
    A = _areas(V, F)
    H = -(igl.cotmatrix(V, F) @ U) / A[:, None]
    return H - _rowdot(U, H)[:, None] * U, A


def _rms(G, A):
    return float(np.sqrt(A @ _rowdot(G, G) / (4.0 * np.pi)))


def _mobius_projection(U, G, A):
    """A-weighted least-squares projection of G off the Möbius dilation fields
    Z_k(U_i) = e_k - (e_k . U_i) U_i, k = 1..3 (solved with numpy lstsq)."""
    sq = np.sqrt(A)[:, None]
    Z = np.stack([np.eye(3)[k] - np.outer(U[:, k], np.ones(3)) * U for k in range(3)], axis=2)
    Zw = (Z * sq[:, :, None]).reshape(-1, 3)
    lam = np.linalg.lstsq(Zw, (G * sq).ravel(), rcond=None)[0]
    return G - Z @ lam


# ---------------------------------------------------------------- gradient

def test_euclidean_gradient_is_minus_LU(mesh, rng):
    """dE/dU = -L U: central differences of the quadratic energy are exact up to rounding."""
    V, F = mesh("fish_lowres.obj")
    L = igl.cotmatrix(V, F)
    U = _unit(rng.normal(size=V.shape))
    grad = -(L @ U)
    for _ in range(3):
        D = rng.normal(size=V.shape)
        h = 1e-3
        fd = (harmonic_energy(V, F, U + h * D) - harmonic_energy(V, F, U - h * D)) / (2.0 * h)
        assert fd == pytest.approx(np.sum(grad * D), rel=1e-8)


def test_riemannian_gradient_matches_finite_differences_on_the_sphere(mesh, rng):
    V, F = mesh("fish_lowres.obj")
    U = gauss_map(V, F)
    G, A = _riemannian_gradient(V, F, U)
    assert np.abs(_rowdot(G, U)).max() < 1e-12
    h = 1e-5
    for _ in range(3):
        D = rng.normal(size=V.shape)
        D -= _rowdot(D, U)[:, None] * U  # random tangent direction
        fd = (harmonic_energy(V, F, _unit(U + h * D))
              - harmonic_energy(V, F, _unit(U - h * D))) / (2.0 * h)
        assert fd == pytest.approx(A @ _rowdot(G, D), rel=1e-6)
    # Along the Cayley curve of Algorithm 1 the slope is -<G, G>_M (the Armijo term).
    fd = (harmonic_energy(V, F, cayley_step(U, G, h))
          - harmonic_energy(V, F, cayley_step(U, G, -h))) / (2.0 * h)
    assert fd == pytest.approx(-(A @ _rowdot(G, G)), rel=1e-6)


def test_reported_energy_and_gradient_norm_are_independent_quantities(mesh):
    """Algorithm 1's per-iterate energy and RMS Riemannian gradient (paper settings) equal
    -1/2 tr(U^T L U) and sqrt(sum A_i |G_i|^2 / 4 pi) recomputed here; the Zhang-Hager
    search keeps every energy below the initial one."""
    V, F = mesh("fish_lowres.obj")
    U0 = gauss_map(V, F)
    seen = []

    def record(k, U, E, g):
        seen.append((k, U.copy(), E, g))

    res = harmonic_map(V, F, U0, max_iter=40, callback=record, **PAPER)
    assert [s[0] for s in seen] == list(range(1, res.nit + 1))
    assert len(res.energy_history) == len(res.grad_norm_history) == res.nit + 1
    for k, U, E, g in [(0, U0, res.energy_history[0], res.grad_norm_history[0]), *seen]:
        assert E == pytest.approx(harmonic_energy(V, F, U), rel=1e-12)
        assert g == pytest.approx(_rms(*_riemannian_gradient(V, F, U)), rel=1e-9)
        assert E == res.energy_history[k] and g == res.grad_norm_history[k]
    assert max(res.energy_history) == res.energy_history[0]
    assert res.energy < res.energy_history[0]


def test_mobius_projected_gradient_norm(mesh):
    """With Möbius normalization the reported gradient is G projected (area-weighted) off
    the three infinitesimal Möbius dilations, of the Möbius-centered initial map."""
    V, F = mesh("goathead.obj")
    U0 = gauss_map(V, F)
    res = harmonic_map(V, F, U0, laplacian_kind="cotan", metric="L2", mobius=True, max_iter=0)
    U, _ = mobius_center(U0, _areas(V, F))
    G, A = _riemannian_gradient(V, F, U)
    P = _mobius_projection(U, G, A)
    assert np.linalg.norm(A @ P) < 1e-10 * np.linalg.norm(A @ G)  # centroid does not move
    assert res.grad_norm_history[0] == pytest.approx(_rms(P, A), rel=1e-8)
    assert res.energy_history[0] == pytest.approx(harmonic_energy(V, F, U), rel=1e-10)


# ---------------------------------------------------------------- critical points

@pytest.mark.parametrize("options", [PAPER, {}], ids=["paper", "default"])
def test_identity_of_the_symmetric_icosphere_is_a_critical_point(icosphere, options):
    """At refinement level 1 every vertex is fixed by a symmetry containing two mirror
    planes through it, so -L V is radial: the identity is an exact critical point."""
    V, F = icosphere(1)
    assert _rms(*_riemannian_gradient(V, F, V)) < 1e-13
    res = harmonic_map(V, F, V, **options)
    assert res.converged and res.nit == 0
    assert np.abs(res.U - V).max() < 1e-8
    assert res.folds == 0


def test_identity_gradient_of_finer_icospheres_is_a_discretisation_error(icosphere):
    rms = []
    for level in (2, 3, 4):
        V, F = icosphere(level)
        rms.append(_rms(*_riemannian_gradient(V, F, V)))
    assert rms[0] > rms[1] > rms[2] > 0
    assert rms[2] < rms[0] / 4.0


def test_converges_from_a_perturbed_sphere_map_to_a_rotation(icosphere, fit_rotation, rng):
    V, F = icosphere(2)
    U0 = _unit(V + 0.05 * rng.normal(size=V.shape))
    res = harmonic_map(V, F, U0)
    assert res.converged and res.grad_norm <= 1e-5
    assert res.folds == 0
    assert np.abs(np.linalg.norm(res.U, axis=1) - 1.0).max() < 1e-13
    assert res.energy < res.energy_history[0]
    Q, residual = fit_rotation(V, res.U)
    assert np.linalg.det(Q) > 0
    assert residual < 5e-3  # the discrete harmonic map of a level-2 icosphere is ~1e-3 off


# ---------------------------------------------------------------- stopping, arguments

def test_max_iter_stops_without_convergence(mesh):
    V, F = mesh("fish_lowres.obj")
    res = harmonic_map(V, F, gauss_map(V, F), max_iter=3)
    assert not res.converged and not res.success
    assert res.nit == 3 and "max_iter" in res.message
    assert len(res.energy_history) == 4


def test_a_run_the_gauge_undoes_stops_where_its_energy_stalled(mesh):
    """On the stepped shaft (tests/data) the Gauss map's descent collapses toward a point: without
    the gauge it reaches E ~ 0, with it every step is undone by the re-centering, and the run
    used to go on so until ``max_iter``.  It now stops, not converged, after the energy stalled;
    going on does not lower the energy further."""
    V, F = mesh("stepped_shaft.obj")
    U0 = gauss_map(V, F)
    assert harmonic_map(V, F, U0, mobius=False).energy < 1e-6 * 4 * np.pi   # the collapse
    res = harmonic_map(V, F, U0)
    assert not res.converged and "Möbius orbit" in res.message
    assert res.nit < 200 and res.mobius_steps >= 50
    E = np.asarray(res.energy_history)
    assert E[-50] - E[-1] <= 1e-6 * E[-1]
    more = harmonic_map(V, F, res.U, max_iter=1000)
    assert min(more.energy_history) >= res.energy * (1.0 - 1e-6)


def test_a_converging_run_is_not_stopped_by_the_stall_test(mesh):
    """Late iterations of a converging run change the energy by less than the stall test's
    share too (here with the paper's L2 metric, from iteration 247 of 352); the run is seldom
    re-centered, so it goes on to ``gtol``."""
    V, F = mesh("fish_lowres.obj")
    res = harmonic_map(V, F, gauss_map(V, F), metric="L2")
    assert res.converged and res.grad_norm <= 1e-5
    E = np.asarray(res.energy_history)
    assert E[-50] - E[-1] <= 1e-6 * E[-1]   # the energy alone would have stopped it


def test_bad_arguments_are_value_errors(icosphere):
    V, F = icosphere(1)
    with pytest.raises(ValueError, match="U0 has 41 rows; expected 42"):
        harmonic_map(V, F, V[:-1])
    with pytest.raises(ValueError, match="unknown metric 'H2'"):
        harmonic_map(V, F, V, metric="H2")
    with pytest.raises(ValueError, match="unknown laplacian_kind 'uniform'"):
        harmonic_map(V, F, V, laplacian_kind="uniform")
    for gtol in (0.0, -1.0, float("nan")):
        with pytest.raises(ValueError, match="gtol must be"):
            harmonic_map(V, F, V, gtol=gtol)
    with pytest.raises(ValueError, match="max_iter must be an integer >= 0"):
        harmonic_map(V, F, V, max_iter=2.5)
    with pytest.raises(ValueError, match="1 row with NaN"):
        U0 = V.copy()
        U0[7, 1] = np.inf
        harmonic_map(V, F, U0)
    with pytest.raises(ValueError, match="unknown option"):
        harmonic_map(V, F, V, max_rounds_typo=3)
    with pytest.raises(ValueError, match="U0 has 1 zero row"):  # was "|c| = nan" (Möbius)
        harmonic_map(V, F, np.r_[np.zeros((1, 3)), V[1:]])


# ---------------------------------------------------------------- fold barrier

@pytest.mark.parametrize("options", [PAPER, {}], ids=["paper", "default"])
def test_fold_barrier_never_folds_a_face(mesh, options):
    """With fold_barrier, the folded faces of every iterate are a subset of those of
    all earlier iterates (the start is Möbius-centered first when mobius is on)."""
    V, F = mesh("fish_lowres.obj")
    U0 = star_map(V, F, gauss_map(V, F))
    start = U0
    if options.get("mobius", True):  # harmonic_map centers the start before the barrier
        area = vertex_areas(V, F)
        start, _ = mobius_center(U0, area * (4.0 * np.pi / area.sum()))
    allowed = folded_faces(F, start)
    assert allowed.any()  # the start has folds: some may unfold, none may appear
    violations = []

    def check(k, U, E, g):
        now = folded_faces(F, U)
        violations.append(int(np.count_nonzero(now & ~allowed)))
        allowed[:] &= now

    res = harmonic_map(V, F, U0, fold_barrier=True, max_iter=3000, callback=check, **options)
    assert len(violations) == res.nit > 0
    assert max(violations) == 0
    assert count_folds(F, res.U) <= count_folds(F, start)


def test_result_does_not_depend_on_wall_clock_time(mesh, monkeypatch):
    """Two runs must give bit-identical maps whatever the machine load: a run whose clock
    races ahead (every perf_counter call is an hour later) must equal a normal run."""
    V, F = mesh("fish_lowres.obj")
    U0 = star_map(V, F, gauss_map(V, F))
    reference = harmonic_map(V, F, U0, fold_barrier=True, max_iter=3000)
    assert reference.frozen > 0  # the barrier froze vertices (H1 refactorization path)
    clock = itertools.count(1)
    monkeypatch.setattr(time, "perf_counter", lambda: 3600.0 * next(clock))
    fast = harmonic_map(V, F, U0, fold_barrier=True, max_iter=3000)
    monkeypatch.undo()
    assert fast.nit == reference.nit
    assert np.array_equal(fast.U, reference.U)

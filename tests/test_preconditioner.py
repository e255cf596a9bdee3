"""igl_spheremap.optimize.preconditioner: the H1 metric solvers, and their use in Algorithm 1."""

import sys

import numpy as np
import pyamg
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from igl_spheremap import (MapOptions, count_folds, folded_faces, gauss_map, harmonic_map,
                           mobius_center, star_map)
from igl_spheremap.optimize.amg import AMG_STRENGTH_THETA, smoothed_aggregation_levels
from igl_spheremap.mesh.operators import laplacian, vertex_areas
from igl_spheremap.optimize.preconditioner import (AUTO_DIRECT_MAX_SIZE, cholmod_available, h1_preconditioner, resolve_h1_solver)

needs_cholmod = pytest.mark.skipif(not cholmod_available(),
                                   reason="scikit-sparse 0.4 (the cholmod extra) not installed")


def _metric(V, F):
    """K = M - L (intrinsic Delaunay Laplacian, barycentric areas scaled to 4 pi) and the areas."""
    A = vertex_areas(V, F)
    A *= 4.0 * np.pi / A.sum()
    return (sp.diags(A) - laplacian(V, F)).tocsr(), A


def _gradient(V, F, U, A):
    """Tangential part of H = -M^{-1} L U (the L2 Riemannian gradient)."""
    H = -(laplacian(V, F) @ U) / A[:, None]
    return H - np.einsum("ij,ij->i", U, H)[:, None] * U


@pytest.mark.parametrize("solver", ["direct", "superlu",
                                    pytest.param("cholmod", marks=needs_cholmod)])
def test_direct_solvers_are_the_exact_inverse(solver, ellipsoid, rng):
    V, F = ellipsoid(3)
    K, _ = _metric(V, F)
    B = rng.normal(size=(K.shape[0], 3))
    ref = spla.spsolve(K.tocsc(), B)
    solve = h1_preconditioner(K, solver)
    X = solve(B)
    assert X.shape == B.shape
    assert np.abs(X - ref).max() <= 1e-10 * np.abs(ref).max()
    x1 = solve(B[:, 1])
    assert x1.shape == (K.shape[0],)
    assert np.abs(x1 - ref[:, 1]).max() <= 1e-10 * np.abs(ref).max()


def test_direct_is_cholmod_when_installed_else_superlu(ellipsoid, rng, monkeypatch):
    """``"direct"`` gives bit for bit the backend it stands for; without
    scikit-sparse it is SuperLU and ``"cholmod"`` says what to install."""
    V, F = ellipsoid(3)
    K, _ = _metric(V, F)
    B = rng.normal(size=(K.shape[0], 3))
    superlu = h1_preconditioner(K, "superlu")(B)
    if cholmod_available():
        cholmod = h1_preconditioner(K, "cholmod")(B)
        assert np.array_equal(h1_preconditioner(K, "direct")(B), cholmod)
    for name in ("sksparse", "sksparse.cholmod", "sksparse_minimal",
                 "sksparse_minimal._cholespy_core"):  # as if no CHOLMOD package were installed
        monkeypatch.setitem(sys.modules, name, None)
    assert not cholmod_available()
    assert np.array_equal(h1_preconditioner(K, "direct")(B), superlu)
    with pytest.raises(ModuleNotFoundError, match="scikit-sparse"):
        h1_preconditioner(K, "cholmod")


def test_amg_cycle_is_pyamg_v_cycle_on_every_column(mesh, rng):
    """Our multi-column V-cycle equals pyamg's own one-rhs cycle on the same hierarchy
    (forward Gauss-Seidel before and backward after the coarse-grid correction, exact
    coarsest solve), column by column."""
    from pyamg.multilevel import MultilevelSolver
    from pyamg.relaxation.smoothing import change_smoothers

    V, F = mesh("hippocampus.obj")
    K, _ = _metric(V, F)
    B = rng.normal(size=(K.shape[0], 3))
    A, P, R = smoothed_aggregation_levels(K)
    levels = []
    for i, Ai in enumerate(A):
        lvl = MultilevelSolver.Level()
        lvl.A = sp.csr_matrix(Ai)
        if i < len(P):
            lvl.P, lvl.R = sp.csr_matrix(P[i]), sp.csr_matrix(R[i])
        levels.append(lvl)
    ml = MultilevelSolver(levels, coarse_solver="pinv")
    change_smoothers(ml, ("gauss_seidel", {"sweep": "forward"}),
                     ("gauss_seidel", {"sweep": "backward"}))
    assert len(ml.levels) > 2
    ref = np.column_stack([ml.solve(B[:, j], x0=np.zeros(K.shape[0]), maxiter=1, tol=1e-300)
                           for j in range(3)])
    X = h1_preconditioner(K, "amg")(B)
    assert X.shape == B.shape
    assert np.abs(X - ref).max() <= 1e-10 * np.abs(ref).max()
    x1 = h1_preconditioner(K, "amg")(B[:, 2])
    assert np.abs(x1 - ref[:, 2]).max() <= 1e-10 * np.abs(ref).max()


def test_amg_is_spd_and_spectrally_equivalent_to_the_inverse(mesh):
    """One V-cycle P is symmetric positive definite and 0 < eig(P K) <= 1 (each cycle
    reduces the K-norm of the error; dense eigenvalues as the reference)."""
    V, F = mesh("fish_lowres.obj")
    K, _ = _metric(V, F)
    n = K.shape[0]
    P = h1_preconditioner(K, "amg")(np.eye(n))
    assert np.abs(P - P.T).max() <= 1e-12 * np.abs(P).max()
    with MapOptions().blas_limit():  # dense LAPACK on a loaded 2-core machine
        assert np.linalg.eigvalsh(0.5 * (P + P.T)).min() > 0
        # eig(P K) = eig(C^T K C) with P = C C^T (Cholesky).
        C = np.linalg.cholesky(0.5 * (P + P.T))
        mu = np.linalg.eigvalsh(C.T @ K.toarray() @ C)
    assert mu.max() <= 1.0 + 1e-9
    assert mu.min() > 0.3  # error reduction per cycle better than 0.7 in the K-norm


def test_amg_cycles_converge_to_the_exact_solve(ellipsoid, rng):
    V, F = ellipsoid(4)
    K, A = _metric(V, F)
    B = rng.normal(size=(K.shape[0], 3)) * A[:, None]
    ref = spla.spsolve(K.tocsc(), B)

    def knorm(E):
        return np.sqrt(np.sum(E * (K @ E)))

    errors = [knorm(h1_preconditioner(K, "amg", cycles=c)(B) - ref) / knorm(ref)
              for c in (1, 2, 4, 8)]
    assert all(b < 0.7 * a for a, b in zip(errors, errors[1:]))
    assert errors[-1] < 1e-2


def test_amg_direction_is_a_descent_direction_near_the_exact_one(mesh):
    """From the Gauss map of a real mesh: <G, P M G>_M > 0 and the AMG direction
    points where the exact H1 direction K^{-1} M G does."""
    V, F = mesh("hippocampus.obj")
    K, A = _metric(V, F)
    U = gauss_map(V, F)
    G = _gradient(V, F, U, A)
    rhs = G * A[:, None]
    X_amg = h1_preconditioner(K, "amg")(rhs)
    X_ref = spla.spsolve(K.tocsc(), rhs)
    assert np.sum(rhs * X_amg) > 0
    cos = np.sum(X_amg * (K @ X_ref)) / np.sqrt(np.sum(X_amg * (K @ X_amg)) *
                                                np.sum(X_ref * (K @ X_ref)))
    assert cos > 0.8


@pytest.mark.parametrize("name", ["hippocampus.obj", "ellipsoid"])
def test_converged_maps_agree_between_amg_and_direct(name, mesh, ellipsoid, fit_rotation):
    """Same fixed point: equal energies, and the Möbius-centered maps differ by a rotation only."""
    V, F = ellipsoid(4) if name == "ellipsoid" else mesh(name)
    U0 = gauss_map(V, F)
    runs = {s: harmonic_map(V, F, U0, h1_solver=s, gtol=1e-7) for s in ("direct", "amg")}
    assert all(r.converged for r in runs.values())
    # Equal up to the discrete energy's slight variation along the Möbius orbit.
    assert runs["amg"].energy == pytest.approx(runs["direct"].energy, rel=1e-7)
    A = vertex_areas(V, F)
    Ud, _ = mobius_center(runs["direct"].U, A)
    Ua, _ = mobius_center(runs["amg"].U, A)
    Q, residual = fit_rotation(Ua, Ud)
    assert np.linalg.det(Q) > 0
    assert residual < 1e-5


def test_auto_is_direct_up_to_the_threshold_and_amg_above():
    assert resolve_h1_solver("auto", AUTO_DIRECT_MAX_SIZE) == "direct"
    assert resolve_h1_solver("auto", AUTO_DIRECT_MAX_SIZE + 1) == "amg"
    for name in ("direct", "amg", "cholmod", "superlu"):
        assert resolve_h1_solver(name, 10) == name
    with pytest.raises(ValueError, match="h1_solver"):
        resolve_h1_solver("cholesky", 10)


def test_unknown_solver_or_cycles_raise(ellipsoid):
    V, F = ellipsoid(2)
    K, _ = _metric(V, F)
    with pytest.raises(ValueError, match="H1 solver"):
        h1_preconditioner(K, "cholesky")
    with pytest.raises(ValueError, match="cycles"):
        h1_preconditioner(K, "amg", cycles=0)
    with pytest.raises(ValueError, match="square"):
        h1_preconditioner(K[:, :-1], "amg")
    with pytest.raises(ValueError, match="h1_solver"):
        harmonic_map(V, F, gauss_map(V, F), h1_solver="cholesky")


@pytest.mark.parametrize("solver", ["direct", "amg"])
def test_h1_steps_turn_no_vertex_by_more_than_90_degrees(solver, mesh):
    """The H1 trust region: consecutive iterates (no re-centering with mobius=False)
    differ per vertex by at most a quarter turn."""
    V, F = mesh("fish_lowres.obj")
    seen = [gauss_map(V, F)]
    res = harmonic_map(V, F, seen[0], mobius=False, h1_solver=solver, max_iter=40,
                       callback=lambda k, U, E, g: seen.append(U.copy()))
    assert res.nit == len(seen) - 1 > 5
    cos = [np.einsum("ij,ij->i", a, b).min() for a, b in zip(seen, seen[1:])]
    assert min(cos) >= -1e-12


def test_amg_on_a_free_set_with_isolated_vertices(mesh, rng):
    """The fold barrier restricts K to the free vertices; with most of them frozen
    the free set has isolated vertices (and AMG levels without connections).
    The cycle must still converge toward the exact solve (spsolve reference)."""
    V, F = mesh("hippocampus.obj")
    K, _ = _metric(V, F)
    for frozen_share in (0.5, 0.97, 0.99):
        free = rng.random(K.shape[0]) > frozen_share
        Kf = K[free][:, free]
        B = rng.normal(size=(Kf.shape[0], 3))
        ref = spla.spsolve(Kf.tocsc(), B)
        E = h1_preconditioner(Kf, "amg")(B) - ref
        assert np.sqrt(np.sum(E * (Kf @ E)) / np.sum(ref * (Kf @ ref))) < 0.5


def test_amg_hierarchy_is_a_smoothed_aggregation_hierarchy(mesh):
    """Level by level, against pyamg's building blocks and a dense eigensolver: Galerkin
    coarse operators A_{l+1} = R_l A_l P_l with R = P^T, and P_l = (I - w D^-1 A_l) T_l
    with T_l pyamg's tentative prolongator of the strength graph's standard aggregates
    and w = (4/3) / rho(D^-1 A_l), rho within 10% below the true spectral radius."""
    from pyamg.aggregation import fit_candidates, standard_aggregation
    from pyamg.strength import symmetric_strength_of_connection

    V, F = mesh("fish_lowres.obj")
    K, _ = _metric(V, F)
    A, P, R = smoothed_aggregation_levels(K)
    assert len(A) > 2 and A[-1].shape[0] <= 10
    B = np.ones((K.shape[0], 1))
    for l in range(len(P)):
        Al = sp.csr_matrix(A[l])
        assert abs(sp.csr_matrix(R[l]) - sp.csr_matrix(P[l]).T).max() == 0
        assert abs(sp.csr_matrix(A[l + 1]) - R[l] @ Al @ P[l]).max() <= 1e-12 * abs(Al).max()
        C = symmetric_strength_of_connection(A[l], theta=AMG_STRENGTH_THETA)
        T, B = fit_candidates(standard_aggregation(C)[0], B)
        DA_T = sp.diags(1.0 / Al.diagonal()) @ Al @ T
        D = (T - P[l]).toarray().ravel()
        w = float(D @ DA_T.toarray().ravel() / np.sum(DA_T.toarray() ** 2))
        assert np.abs((T - w * DA_T - P[l]).toarray()).max() <= 1e-12
        d = 1.0 / np.sqrt(Al.diagonal())
        rho = np.linalg.eigvalsh((sp.diags(d) @ Al @ sp.diags(d)).toarray()).max()
        assert 0.9 * rho <= (4.0 / 3.0) / w <= rho * (1 + 1e-9)


def test_amg_setup_leaves_the_global_random_state_alone(ellipsoid):
    V, F = ellipsoid(3)
    K, _ = _metric(V, F)
    np.random.seed(7)
    expected = np.random.rand(3)
    np.random.seed(7)
    h1_preconditioner(K, "amg")
    assert np.array_equal(np.random.rand(3), expected)


def test_fold_barrier_with_amg_never_folds_and_is_reproducible(mesh):
    """fold_barrier with the AMG solver: no face folds that was not folded before
    (callback check on every iterate), vertices get frozen (AMG set up again on
    the free set), and two runs give bit-identical maps."""
    V, F = mesh("fish_lowres.obj")
    U0 = star_map(V, F, gauss_map(V, F))
    area = vertex_areas(V, F)
    start, _ = mobius_center(U0, area * (4.0 * np.pi / area.sum()))
    allowed = folded_faces(F, start)
    violations = []

    def check(k, U, E, g):
        now = folded_faces(F, U)
        violations.append(int(np.count_nonzero(now & ~allowed)))
        allowed[:] &= now

    res = harmonic_map(V, F, U0, fold_barrier=True, max_iter=3000, h1_solver="amg",
                       callback=check)
    assert len(violations) == res.nit > 25
    assert max(violations) == 0
    assert res.frozen > 0
    assert count_folds(F, res.U) <= count_folds(F, start)
    again = harmonic_map(V, F, U0, fold_barrier=True, max_iter=3000, h1_solver="amg")
    assert np.array_equal(again.U, res.U)

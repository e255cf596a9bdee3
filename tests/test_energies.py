"""igl_spheremap.optimize.energy: the harmonic energy (Eqs. 6, 13) against independent references."""

import igl
import numpy as np
import pytest

from igl_spheremap import MapOptions, mobius_center
from igl_spheremap.optimize.minimize import minimize
from igl_spheremap.optimize.harmonic import HarmonicEnergy
from igl_spheremap.mesh.operators import dirichlet_energy, to_sphere_area, vertex_areas


def _unit(X):
    return X / np.linalg.norm(X, axis=1, keepdims=True)


def _dirichlet_by_faces(V, F, U):
    """1/4 sum over faces and corners of cot(corner angle) |U_i - U_j|^2 (opposite edge ij),
    with the angles computed here from V: the cotangent formula, independently of libigl."""
    E = 0.0
    for c in range(3):
        i, j, k = F[:, c], F[:, (c + 1) % 3], F[:, (c + 2) % 3]
        e1, e2 = V[j] - V[i], V[k] - V[i]
        cot = np.einsum("ij,ij->i", e1, e2) / np.linalg.norm(np.cross(e1, e2), axis=1)
        E += 0.25 * np.sum(cot * np.sum((U[j] - U[k]) ** 2, axis=1))
    return E


def test_value_is_the_cotangent_dirichlet_energy(mesh, rng):
    V, F = mesh("fish_lowres.obj")
    U = _unit(rng.normal(size=V.shape))
    energy = HarmonicEnergy(igl.cotmatrix(V, F), np.ones(len(V)), metric="L2")
    assert energy.value(U) == pytest.approx(_dirichlet_by_faces(V, F, U), rel=1e-11)


def test_gradient_matches_finite_differences(mesh, rng):
    V, F = mesh("goathead.obj")
    energy = HarmonicEnergy(igl.cotmatrix(V, F), np.ones(len(V)), metric="L2")
    U = _unit(rng.normal(size=V.shape))
    g = energy.euclidean_gradient(energy.evaluate(U))
    for _ in range(3):
        D = rng.normal(size=V.shape)
        h = 1e-4
        fd = (energy.value(U + h * D) - energy.value(U - h * D)) / (2 * h)
        assert fd == pytest.approx(np.sum(g * D), rel=1e-8)


def test_l2_and_h1_variants_reach_the_same_harmonic_map(mesh, fit_rotation):
    """One energy, two metrics: the same fixed point (equal energies, maps equal up to a
    rotation after Möbius centering), the H1 variant in far fewer iterations."""
    V, F = mesh("fish_lowres.obj")
    L = igl.cotmatrix(V, F).tocsr()
    area = to_sphere_area(vertex_areas(V, F))
    N = igl.per_vertex_normals(V, F)
    U0 = _unit(N)
    runs = {m: minimize(HarmonicEnergy(L, area, metric=m), U0, F,
                        MapOptions(gtol=1e-6, max_iter=20000))
            for m in ("L2", "H1")}
    assert all(r.converged for r in runs.values())
    assert runs["H1"].nit < runs["L2"].nit / 5
    Ua, _ = mobius_center(runs["L2"].U, area)
    Ub, _ = mobius_center(runs["H1"].U, area)
    # the discrete energy varies slightly along the Möbius orbit, and each run stops somewhere
    # inside the gauge's ball: compare the energies at the same (centred) normalization
    assert dirichlet_energy(L, Ub) == pytest.approx(dirichlet_energy(L, Ua), rel=1e-9)
    Q, residual = fit_rotation(Ua, Ub)
    assert np.linalg.det(Q) > 0 and residual < 1e-4


def test_landmark_energy_value_and_gradient(mesh, rng):
    from igl_spheremap.uses.landmarks import LandmarkEnergy

    V, F = mesh("fish_lowres.obj")
    L = igl.cotmatrix(V, F)
    lm = np.array([5, 100, 400])
    Q = _unit(rng.normal(size=(3, 3)))
    energy = LandmarkEnergy(L, np.ones(len(V)), lm, Q, weight=7.0, metric="L2")
    assert not energy.mobius_invariant
    U = _unit(rng.normal(size=V.shape))
    expected = _dirichlet_by_faces(V, F, U) + 3.5 * np.sum((U[lm] - Q) ** 2)
    assert energy.value(U) == pytest.approx(expected, rel=1e-11)
    g = energy.euclidean_gradient(energy.evaluate(U))
    for _ in range(3):
        D = rng.normal(size=V.shape)
        h = 1e-4
        fd = (energy.value(U + h * D) - energy.value(U - h * D)) / (2 * h)
        assert fd == pytest.approx(np.sum(g * D), rel=1e-8)


@pytest.mark.parametrize("p", [2.0, 3.0, 4.0, 2.5])
def test_p_harmonic_gradient_matches_finite_differences(mesh, rng, p):
    from igl_spheremap.uses.p_harmonic import PHarmonicEnergy

    V, F = mesh("goathead.obj")
    energy = PHarmonicEnergy(V, F, p, metric="L2")
    U = _unit(rng.normal(size=V.shape))
    g = energy.euclidean_gradient(energy.evaluate(U))
    for _ in range(2):
        D = rng.normal(size=V.shape)
        h = 1e-5
        fd = (energy.value(U + h * D) - energy.value(U - h * D)) / (2 * h)
        assert fd == pytest.approx(np.sum(g * D), rel=1e-6)


def test_p_equal_2_is_the_harmonic_energy(mesh, rng):
    """Eq. 8 with p = 2 on the mesh scaled to area 4 pi is -1/2 tr(U^T L U) with the
    cotangent Laplacian (scale invariant), computed here per face."""
    from igl_spheremap.uses.p_harmonic import PHarmonicEnergy

    V, F = mesh("fish_lowres.obj")
    U = _unit(rng.normal(size=V.shape))
    assert PHarmonicEnergy(V, F, 2).value(U) == pytest.approx(_dirichlet_by_faces(V, F, U),
                                                               rel=1e-10)
    assert PHarmonicEnergy(V, F, 2).mobius_invariant and not PHarmonicEnergy(V, F, 3).mobius_invariant
    with pytest.raises(ValueError, match="p must be"):
        PHarmonicEnergy(V, F, 1.5)


def test_p_harmonic_map_evens_out_areas(mesh):
    """From the conformal map, p = 4 lowers the area distortion (mean |log area ratio|)
    and raises the angle distortion, fold-free."""
    import igl_spheremap as sm

    V, F = mesh("hippocampus.obj")
    base = sm.spherical_conformal_map(V, F)
    res = sm.p_harmonic_map(V, F, base.U, 4.0)
    assert res.converged and sm.count_folds(F, res.U) == 0
    area = np.abs(sm.area_distortion(V, F, res.U)).mean()
    area0 = np.abs(sm.area_distortion(V, F, base.U)).mean()
    assert area < area0
    assert sm.angle_distortion(V, F, res.U).mean() > sm.angle_distortion(V, F, base.U).mean()


def test_p_harmonic_map_from_a_reflected_map_is_no_success(icosphere):
    """A mirror image has every face inverted: the fold barrier cannot apply, the map stays
    folded, and the result says so (folds counted by the determinant) and warns."""
    from igl_spheremap import SphericalMapWarning, p_harmonic_map

    V, F = icosphere(3)
    V = V * np.array([1.0, 1.4, 0.8])
    U0 = V / np.linalg.norm(V, axis=1, keepdims=True) * np.array([-1.0, 1.0, 1.0])
    with pytest.warns(SphericalMapWarning, match="folded faces"):
        res = p_harmonic_map(V, F, U0, 4.0, max_iter=50)
    det = np.linalg.det(np.stack([res.U[F[:, k]] for k in range(3)], axis=1))
    assert res.folds == np.count_nonzero(det <= 0) > 0
    assert not res.success
    # the message says so too, not only the warning (it gave the stopping rule alone before)
    assert res.message.startswith(f"{res.folds} folded faces in the map; ")


def test_an_energy_refuses_a_metric_name_and_runs_with_a_metric_object(icosphere):
    """README's recipe for a new energy: ``Energy.__init__(area, metric)`` needs a metric
    object; the name "L2" was accepted and crashed inside minimize ('str' object has no
    attribute 'setup').  Built with make_metric, the cotangent Dirichlet energy reaches a
    fold-free critical point whose value is libigl's -1/2 tr(U^T L U)."""
    import igl_spheremap as sm
    from igl_spheremap.optimize.direction import make_metric
    from igl_spheremap.optimize.energy import Energy, Evaluation
    from igl_spheremap.optimize.minimize import minimize

    V, F = icosphere(2)
    V = V * np.array([1.0, 1.5, 3.0])
    V = V * np.sqrt(4 * np.pi / (igl.doublearea(V, F).sum() / 2))
    L = igl.cotmatrix(V, F)
    area = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_BARYCENTRIC).diagonal()

    class Dirichlet(Energy):
        mobius_invariant = True

        def evaluate(self, U):
            LU = L @ U
            return Evaluation(U=U, value=-0.5 * np.sum(U * LU), LU=LU)

        def euclidean_gradient(self, ev):
            return -ev.LU

    with pytest.raises(TypeError, match=r"metric must be a metric object, not str 'L2'.*"
                                        r"make_metric\(name, L, area\)"):
        Dirichlet(area, "L2")
    for name in ("L2", "H1"):
        run = minimize(Dirichlet(area, make_metric(name, L, area)), sm.gauss_map(V, F), F)
        assert run.converged and sm.count_folds(F, run.U) == 0
        assert run.energy == pytest.approx(-0.5 * np.trace(run.U.T @ (L @ run.U)), rel=1e-12)

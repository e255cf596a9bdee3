"""The area-balanced sphere: the symmetric Dirichlet energy against finite differences and its
invariances, and spherical_conformal_map(kind="area_balanced") against the conformal map."""

import igl
import numpy as np
import pytest

from conftest import load_mesh
from igl_spheremap import area_balanced_map, area_distortion, spherical_conformal_map
from igl_spheremap.optimize.distortion import SymmetricDirichletEnergy
from igl_spheremap.sphere.folds import folds_after_rounding


@pytest.fixture(scope="module")
def hippocampus():
    V, F = load_mesh("hippocampus.obj")
    return V, F, spherical_conformal_map(V, F, precision="float32")


def test_gradient_invariance_and_lower_bound(hippocampus):
    V, F, conformal = hippocampus
    U = conformal.U
    E = SymmetricDirichletEnergy(V, F)
    ev = E.evaluate(U)
    G = E.euclidean_gradient(ev)
    D = np.random.default_rng(0).normal(size=U.shape)
    h = 1e-6
    fd = (E.evaluate(U + h * D).value - E.evaluate(U - h * D).value) / (2 * h)
    assert fd == pytest.approx(float(np.vdot(G, D)), rel=1e-4)
    c, s = np.cos(0.7), np.sin(0.7)
    R = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    assert E.evaluate(U @ R.T).value == pytest.approx(ev.value, rel=1e-12)
    assert ev.value >= 2.0 * 4 * np.pi  # e >= 2 per unit area, area 4 pi
    # an isometry (the surface itself, scaled to area 4 pi) has energy 8 pi exactly
    scale = np.sqrt(4 * np.pi / (igl.doublearea(V, F).sum() / 2))
    assert E.evaluate(V * scale).value == pytest.approx(8 * np.pi, rel=1e-9)


def test_area_balanced_kind_lowers_area_distortion_and_stays_float32_fold_free(hippocampus):
    V, F, conformal = hippocampus
    res = spherical_conformal_map(V, F, kind="area_balanced", precision="float32")
    assert res.success and res.rounds[-1].kind == "area_balanced"
    a0 = np.abs(area_distortion(V, F, conformal.U)).mean()
    a1 = np.abs(area_distortion(V, F, res.U)).mean()
    assert a1 < 0.6 * a0
    assert res.folds == 0 and res.below_margin == 0
    assert folds_after_rounding(res.F, res.U, 100.0) == 0
    part = area_balanced_map(V, F, conformal.U, precision="float32", max_iter=25)
    assert part.nit == 25 and part.folds == 0
    assert part.energy < part.energy_history[0] and res.rounds[-1].energy < part.energy


def test_bad_kind_and_folded_start(hippocampus):
    V, F, conformal = hippocampus
    with pytest.raises(ValueError, match="kind"):
        spherical_conformal_map(V, F, kind="equiareal")
    U = conformal.U.copy()
    U[F[0, 0]] *= -1
    with pytest.raises(ValueError, match="folded"):
        area_balanced_map(V, F, U)

"""Failures inside the pipeline raise clear errors instead of returning NaNs."""

import importlib
import pathlib

import igl
import numpy as np
import pytest
import scipy.sparse.linalg as sla

import igl_spheremap
rounds_mod = importlib.import_module("igl_spheremap.folding.problem")

DATA = pathlib.Path(__file__).parent / "data"


@pytest.fixture(scope="module")
def fish():
    return igl.read_triangle_mesh(str(DATA / "fish_lowres.obj"))


def test_eigensolver_failure_raises_runtime_error(fish, monkeypatch):
    V, F = fish

    def no_convergence(*args, **kwargs):
        raise sla.ArpackNoConvergence("no convergence (simulated)", np.zeros(0), np.zeros((0, 0)))

    monkeypatch.setattr(sla, "eigsh", no_convergence)
    U = igl_spheremap.gauss_map(V, F)
    with pytest.raises(RuntimeError, match="eigensolver failed"):
        igl_spheremap.star_map(V, F, U)


def test_eigensolver_nan_output_raises_runtime_error(fish, monkeypatch):
    V, F = fish
    real_eigsh = sla.eigsh

    def nan_eigsh(*args, **kwargs):
        lam, X = real_eigsh(*args, **kwargs)
        X[0, 1] = np.nan
        return lam, X

    monkeypatch.setattr(sla, "eigsh", nan_eigsh)
    with pytest.raises(RuntimeError, match="non-finite"):
        igl_spheremap.star_map(V, F, igl_spheremap.gauss_map(V, F))


def test_non_finite_iterate_raises_runtime_error(fish, monkeypatch):
    V, F = fish
    real = rounds_mod.minimize

    def poisoned(*args, **kwargs):
        res = real(*args, **kwargs)
        res.U[3] = np.nan
        return res

    monkeypatch.setattr(rounds_mod, "minimize", poisoned)
    with pytest.raises(RuntimeError, match="non-finite"):
        igl_spheremap.spherical_conformal_map(V, F)


def test_folded_result_warns_and_is_not_success(fish):
    V, F = fish
    with pytest.warns(igl_spheremap.SphericalMapWarning, match="folded faces remain"):
        result = igl_spheremap.spherical_conformal_map(V, F, max_rounds=0, max_iter=1,
                                                       guaranteed_path=False)
    # independent count: flat image triangles whose normal points inward
    U = result.U
    n = np.cross(U[F[:, 1]] - U[F[:, 0]], U[F[:, 2]] - U[F[:, 0]])
    inward = np.einsum("ij,ij->i", n, U[F].sum(axis=1)) <= 0
    assert result.folds == int(inward.sum()) > 0
    assert not result.success
    assert np.all(np.isfinite(result.U))

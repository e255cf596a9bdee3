"""igl_spheremap.optimize.manifold.cayley_step: the curvilinear update of paper Theorem 1 (Eqs. 10-11)."""

import numpy as np
import pytest

from igl_spheremap.optimize.manifold import cayley_step

TAUS = [0.0, 1e-8, 1e-3, 0.1, 1.0, 10.0, 1e3, 1e6, 1e12]


def _unit_rows(rng, n):
    U = rng.normal(size=(n, 3))
    return U / np.linalg.norm(U, axis=1, keepdims=True)


def _tangent(U, H):
    return H - np.einsum("ij,ij->i", U, H)[:, None] * U


def test_tau_zero_is_the_identity(rng):
    U = _unit_rows(rng, 50)
    H = rng.normal(size=U.shape)
    assert np.abs(cayley_step(U, H, 0.0) - U).max() <= 1e-15


@pytest.mark.parametrize("tau", TAUS)
def test_unit_norm_for_tangent_directions(rng, tau):
    """Algorithm 1 passes the projected gradient (U_i . H_i = 0): |Y_i| = 1 for every tau."""
    U = _unit_rows(rng, 2000)
    for scale in (1e-3, 1.0, 1e3):
        H = _tangent(U, scale * rng.normal(size=U.shape))
        Y = cayley_step(U, H, tau)
        assert np.abs(np.linalg.norm(Y, axis=1) - 1.0).max() <= 1e-14


@pytest.mark.parametrize("tau", [1e-8, 1e-3, 0.1, 1.0])
def test_unit_norm_for_general_directions_moderate_steps(rng, tau):
    U = _unit_rows(rng, 2000)
    H = rng.normal(size=U.shape)
    Y = cayley_step(U, H, tau)
    assert np.abs(np.linalg.norm(Y, axis=1) - 1.0).max() <= 1e-14


def test_general_directions_large_steps(rng):
    U = _unit_rows(rng, 2000)
    random_H = rng.normal(size=U.shape)
    normal_H = 3.0 * U + 1e-9 * rng.normal(size=U.shape)
    for tau in (10.0, 1e3, 1e6, 1e9):
        for H in (random_H, normal_H):
            Y = cayley_step(U, H, tau)
            assert np.abs(np.linalg.norm(Y, axis=1) - 1.0).max() <= 1e-14
        # Same step as for the tangential part of H (exact identity of Eq. 10).
        assert np.abs(cayley_step(U, random_H, tau)
                      - cayley_step(U, _tangent(U, random_H), tau)).max() <= 1e-12
        if tau <= 1e6:  # beyond, tau * eps * |H| / |H_tan| makes the step ill-conditioned
            assert np.abs(cayley_step(U, normal_H, tau)
                          - cayley_step(U, _tangent(U, normal_H), tau)).max() <= 1e-10


def test_equals_the_cayley_transform_eq10(rng):
    """Y_i = (I + tau/2 A_i)^{-1} (I - tau/2 A_i) U_i with A_i = H_i U_i^T - U_i H_i^T,
    solved per vertex; also the implicit form Y = U - tau/2 A (U + Y) of Eq. 11."""
    U = _unit_rows(rng, 12)
    H = rng.normal(size=U.shape)
    for tau in (1e-3, 0.5, 3.0, 40.0):
        Y = cayley_step(U, H, tau)
        for i in range(U.shape[0]):
            A = np.outer(H[i], U[i]) - np.outer(U[i], H[i])
            eye = np.eye(3)
            ref = np.linalg.solve(eye + 0.5 * tau * A, (eye - 0.5 * tau * A) @ U[i])
            assert np.allclose(Y[i], ref, rtol=0, atol=1e-13)
            assert np.allclose(Y[i], U[i] - 0.5 * tau * A @ (U[i] + Y[i]), rtol=0, atol=1e-12)


def test_is_the_rotation_by_the_cayley_angle(rng):
    """For tangent H the Cayley transform rotates U_i towards -H_i by 2 arctan(tau |H_i| / 2)."""
    U = _unit_rows(rng, 500)
    H = _tangent(U, rng.normal(size=U.shape))
    h = np.linalg.norm(H, axis=1)
    for tau in (0.01, 1.0, 30.0, 1e5):
        theta = 2.0 * np.arctan(0.5 * tau * h)
        ref = np.cos(theta)[:, None] * U - np.sin(theta)[:, None] * H / h[:, None]
        assert np.abs(cayley_step(U, H, tau) - ref).max() <= 1e-14


def test_derivative_at_zero_is_minus_the_riemannian_gradient(rng):
    U = _unit_rows(rng, 300)
    H = rng.normal(size=U.shape)
    h = 1e-5
    slope = (cayley_step(U, H, h) - cayley_step(U, H, -h)) / (2.0 * h)
    expected = -_tangent(U, H)
    assert np.abs(slope - expected).max() <= 1e-8 * np.abs(expected).max()

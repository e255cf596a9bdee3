"""Spherical harmonics and the rotation search over SO(3) (igl_spheremap.sphere.harmonics),
against exact quadrature and known rotations."""

import numpy as np
import pytest
import scipy.linalg
from scipy.spatial.transform import Rotation

from igl_spheremap.sphere.harmonics import (best_rotations, correlation, rotation_angle,
                                            rotvec_matrix, sample_grid, sh_coefficients,
                                            standardized_coefficients, wigner_d)


def cubic(X):
    """A degree-3 polynomial on the sphere without rotational symmetry."""
    x, y, z = X.T
    return x + 0.7 * y * z - 0.4 * z ** 3 + 0.3 * x * y + 0.2 * y


def quadrature(f, degree=6):
    """``int f`` over the unit sphere on the Gauss-Legendre grid (exact for degree <= 2 degree + 1)."""
    X, _, w = sample_grid(degree)
    vals = f(X.reshape(-1, 3)).reshape(X.shape[:2])
    return float((vals * w[:, None]).sum() * 2.0 * np.pi / X.shape[1])


@pytest.mark.parametrize("beta", [0.0, 0.4, 1.9, np.pi])
def test_wigner_d_is_the_exponential_of_j_y(beta):
    """Against scipy's matrix exponential of ``-i beta J_y`` (J_y from the ladder operator)."""
    degree = 9
    d = wigner_d(degree, beta)
    for l in range(degree + 1):
        m = np.arange(-l, l)
        Jp = np.diag(np.sqrt(l * (l + 1) - m * (m + 1.0)), -1)
        ref = scipy.linalg.expm(-1j * beta * (Jp - Jp.T) / 2j).real
        block = d[l, degree - l:degree + l + 1, degree - l:degree + l + 1]
        np.testing.assert_allclose(block, ref, atol=1e-13)
    assert np.count_nonzero(d[0]) == 1  # zero outside |m|, |m'| <= l


def test_wigner_d_of_degree_1_and_the_group_law():
    b = 0.7
    d = wigner_d(1, b)[1]  # rows / columns m = -1, 0, 1
    c, s = np.cos(b), np.sin(b)
    np.testing.assert_allclose(d, [[(1 + c) / 2, s / np.sqrt(2), (1 - c) / 2],
                                   [-s / np.sqrt(2), c, s / np.sqrt(2)],
                                   [(1 - c) / 2, -s / np.sqrt(2), (1 + c) / 2]], atol=1e-15)
    a, b = wigner_d(6, 0.3), wigner_d(6, 1.1)
    np.testing.assert_allclose(a @ b, wigner_d(6, 1.4), atol=1e-13)


def test_standardized_coefficients_have_zero_mean_and_unit_variance():
    c = standardized_coefficients(cubic, 5)
    assert abs(c[0, 5]) < 1e-12  # the mean (Y_00 coefficient)
    # Parseval, exact for a band-limited function: int f^2 = 4 pi (variance 1)
    assert np.sum(np.abs(c) ** 2) == pytest.approx(4.0 * np.pi, rel=1e-12)
    assert correlation(c, c, np.eye(3)) == pytest.approx(4.0 * np.pi, rel=1e-12)


def test_correlation_matches_quadrature_of_the_rotated_product():
    degree = 4
    X, theta, w = sample_grid(degree)
    f = sh_coefficients(cubic(X.reshape(-1, 3)).reshape(X.shape[:2]), theta, w, degree)
    g_fun = lambda P: P[:, 2] ** 2 - 0.5 * P[:, 0] + P[:, 0] * P[:, 1]  # noqa: E731
    g = sh_coefficients(g_fun(X.reshape(-1, 3)).reshape(X.shape[:2]), theta, w, degree)
    R = Rotation.from_rotvec([0.4, -1.1, 0.7]).as_matrix()
    expected = quadrature(lambda P: cubic(P) * g_fun(P @ R))  # g(R^T x): rows P R
    assert correlation(f, g, R) == pytest.approx(expected, rel=1e-10)


def test_best_rotations_recovers_a_known_rotation():
    Q = Rotation.from_rotvec([1.2, -0.4, 2.0]).as_matrix()
    f = standardized_coefficients(cubic, 6)  # target h(x)
    g = standardized_coefficients(lambda Y: cubic(Y @ Q.T), 6)  # subject h(Q y)
    (c, R), *_ = best_rotations(f, g, count=2)
    assert np.degrees(rotation_angle(R.T @ Q)) < 0.1
    assert c == pytest.approx(4.0 * np.pi, rel=1e-6)


def test_rotation_vector_and_angle_are_inverse():
    r = np.array([0.3, -1.2, 0.9])
    R = rotvec_matrix(r)
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-14)
    assert np.linalg.det(R) == pytest.approx(1.0)
    assert rotation_angle(R) == pytest.approx(np.linalg.norm(r), rel=1e-12)
    np.testing.assert_allclose(R @ r, r, atol=1e-14)  # the axis is fixed

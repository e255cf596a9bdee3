"""Spherical angles and equirectangular texture coordinates against independent formulas."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from igl_spheremap.sphere.coordinates import (equirectangular_uv, spherical_coordinates, spherical_to_cartesian)


def _random_unit(n, seed):
    X = np.random.default_rng(seed).normal(size=(n, 3))
    return X / np.linalg.norm(X, axis=1, keepdims=True)


def test_angles_match_arccos_and_complex_argument():
    U = _random_unit(2000, 0)
    theta, phi = spherical_coordinates(U)
    # Independent references: theta = arccos z for unit rows, phi = arg(x + i y).
    np.testing.assert_allclose(theta, np.arccos(U[:, 2]), atol=1e-12)
    np.testing.assert_allclose(phi, np.angle(U[:, 0] + 1j * U[:, 1]), atol=1e-12)
    assert theta.min() >= 0.0 and theta.max() <= np.pi
    assert phi.min() >= -np.pi and phi.max() < np.pi


def test_angles_do_not_depend_on_radius():
    U = _random_unit(100, 1)
    for a, b in zip(spherical_coordinates(U), spherical_coordinates(100.0 * U)):
        np.testing.assert_allclose(a, b, atol=1e-14)


def test_special_points_and_phi_range_at_the_seam():
    U = np.array([[0, 0, 1], [0, 0, -1], [1, 0, 0], [0, 1, 0], [-1, 0, 0], [-1, -0.0, 0],
                  [0, -1, 0]], dtype=float)
    theta, phi = spherical_coordinates(U)
    np.testing.assert_allclose(theta, [0, np.pi, np.pi / 2, np.pi / 2, np.pi / 2, np.pi / 2,
                                       np.pi / 2], atol=1e-15)
    # phi of the poles is arbitrary; the -x axis is -pi on both sides of the seam.
    np.testing.assert_allclose(phi[2:], [0, np.pi / 2, -np.pi, -np.pi, -np.pi / 2], atol=1e-15)


def test_cartesian_round_trip():
    U = _random_unit(1000, 2)
    np.testing.assert_allclose(spherical_to_cartesian(*spherical_coordinates(U)), U, atol=1e-14)
    np.testing.assert_allclose(np.linalg.norm(spherical_to_cartesian(*spherical_coordinates(U),
                                                                     radius=100.0), axis=1),
                               100.0, rtol=1e-14)


@settings(max_examples=200, deadline=None)
@given(st.floats(1e-3, np.pi - 1e-3), st.floats(-np.pi, np.pi, exclude_max=True))
def test_angle_round_trip(theta, phi):
    U = spherical_to_cartesian([theta], [phi])
    t2, p2 = spherical_coordinates(U)
    assert abs(t2[0] - theta) < 1e-12
    # compare azimuths on the circle (phi = -pi and pi - eps are neighbours)
    assert abs(np.angle(np.exp(1j * (p2[0] - phi)))) < 1e-10
    assert -np.pi <= p2[0] < np.pi


def test_equirectangular_uv():
    U = _random_unit(500, 3)
    uv = equirectangular_uv(U)
    z = np.clip(U[:, 2], -1, 1)
    np.testing.assert_allclose(uv[:, 1], 1.0 - np.arccos(z) / np.pi, atol=1e-12)
    np.testing.assert_allclose(uv[:, 0], (np.angle(U[:, 0] + 1j * U[:, 1]) + np.pi) / (2 * np.pi),
                               atol=1e-12)
    assert uv.min() >= 0.0 and uv.max() <= 1.0
    poles = equirectangular_uv(np.array([[0.0, 0, 1], [0, 0, -1], [0, -1, 0]]))
    np.testing.assert_allclose(poles[:, 1], [1.0, 0.0, 0.5], atol=1e-15)
    assert poles[2, 0] == pytest.approx(0.25)


def test_rows_that_are_not_points_are_refused():
    """Two columns raised IndexError; a NaN row came back as NaN angles."""
    U = np.eye(3)
    for f in (spherical_coordinates, equirectangular_uv):
        with pytest.raises(ValueError, match=r"\(k, 3\)"):
            f(U[:, :2])
        with pytest.raises(ValueError, match="1 row with NaN"):
            f(np.r_[U[:2], [[np.nan, 0.0, 1.0]]])

"""The per-face distortion of a map between surfaces against exact values: 1 for an isometry,
(a^2 + a^-2) / 2 for a uniform scaling by a, and the singular values of a known stretch."""

import numpy as np
import pytest

from igl_spheremap import icosphere
from igl_spheremap.uses.surface_distortion import face_distortion


@pytest.fixture(scope="module")
def sphere():
    return icosphere(2)


def test_an_isometry_has_distortion_one(sphere):
    V, F = sphere
    c, s = np.cos(0.7), np.sin(0.7)
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    np.testing.assert_allclose(face_distortion(V, F, V @ R.T + [1.0, 2.0, 3.0]), 1.0, atol=1e-12)


@pytest.mark.parametrize("a", [0.5, 2.0, 10.0])
def test_a_uniform_scaling_has_both_singular_values_a(sphere, a):
    V, F = sphere
    np.testing.assert_allclose(face_distortion(V, F, a * V), 0.5 * (a ** 2 + a ** -2), rtol=1e-12)


def test_a_stretch_of_a_flat_triangle_along_an_edge():
    """The triangle (0,0,0), (1,0,0), (0,1,0) with x stretched by 3: singular values 3 and 1."""
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    F = np.array([[0, 1, 2]], dtype=np.int64)
    X = V * [3.0, 1.0, 1.0]
    assert face_distortion(V, F, X)[0] == pytest.approx((9 + 1 + 1 / 9 + 1) / 4, rel=1e-12)


def test_a_degenerate_image_has_an_enormous_distortion(sphere):
    V, F = sphere
    X = V.copy()
    X[F[0, 2]] = 0.5 * (X[F[0, 0]] + X[F[0, 1]])  # face 0 collapses onto an edge
    d = face_distortion(V, F, X)
    assert d[0] > 1e20 and np.all(np.isfinite(d[1:]))

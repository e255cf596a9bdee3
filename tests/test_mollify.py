"""Intrinsic mollification (Sharp, Crane 2020) and the corner weights built on it."""

import igl
import numpy as np

from igl_spheremap.mesh.mollify import MOLLIFY_FACTOR, mollified_edge_lengths, triangle_slack
from igl_spheremap.mesh.shapes import icosphere
from igl_spheremap.optimize.conformal_distortion import corner_weights


def _with_cap(V, F, lift=0.0):
    """``(V, F)`` with a vertex put at the midpoint of edge ``(i, k)`` of face 0 (lifted by
    ``lift`` times the edge's length along the radius): face 0 is split in two at it and the
    third face ``(i, k, j)`` closes the mesh, a corner of (nearly) 180 degrees at ``j``."""
    i, k, a = F[0]
    j = V.shape[0]
    mid = 0.5 * (V[i] + V[k])
    mid = mid + lift * np.linalg.norm(V[i] - V[k]) * mid / np.linalg.norm(mid)
    F = np.vstack([[[i, j, a]], F[1:], [[j, k, a], [i, k, j]]]).astype(np.int64)
    return np.vstack([V, mid]), F


def _slack(lengths):
    """``min_k (l_i + l_j - l_k)`` written out per corner (the reference for ``triangle_slack``)."""
    return np.min([lengths[:, (k + 1) % 3] + lengths[:, (k + 2) % 3] - lengths[:, k]
                   for k in range(3)], axis=0)


def test_triangle_slack_of_known_triangles():
    lengths = np.array([[1.0, 1.0, 1.0], [3.0, 4.0, 5.0], [1.0, 2.0, 3.0], [1.0, 1.0, 3.0]])
    np.testing.assert_array_equal(triangle_slack(lengths), [1.0, 2.0, 0.0, -1.0])
    V, F = _with_cap(*icosphere(2), lift=1e-3)
    np.testing.assert_allclose(triangle_slack(igl.edge_lengths(V, F)),
                               _slack(igl.edge_lengths(V, F)), rtol=1e-15, atol=0)


def test_a_mesh_with_slack_everywhere_keeps_libigls_lengths():
    V, F = icosphere(2)
    lengths, eps = mollified_edge_lengths(V, F)
    assert eps == 0.0
    np.testing.assert_allclose(lengths, igl.edge_lengths(V, F), rtol=1e-15, atol=0)


def test_the_least_eps_gives_every_face_the_slack():
    V, F = _with_cap(*icosphere(2))
    raw = igl.edge_lengths(V, F)
    delta = MOLLIFY_FACTOR * raw.mean()
    assert _slack(raw).min() < 1e-12 * raw.mean()  # the cap is degenerate
    lengths, eps = mollified_edge_lengths(V, F)
    np.testing.assert_allclose(lengths - raw, eps, rtol=0, atol=1e-15)
    np.testing.assert_allclose(eps, delta - _slack(raw).min(), rtol=1e-9)
    np.testing.assert_allclose(_slack(lengths).min(), delta, rtol=1e-6)  # no more than needed
    assert np.all(_slack(lengths) >= delta * (1 - 1e-6))


def test_corner_weights_of_a_mollified_face_are_those_of_the_planar_triangle():
    """``lam_k = (a . b) / 4`` and the area, checked on a planar triangle laid out with the
    mollified lengths (corner 0 at the origin, corner 1 on the x axis)."""
    V, F = _with_cap(*icosphere(1), lift=1e-9)
    lam, area = corner_weights(V, F)
    lengths, _ = mollified_edge_lengths(V, F)
    l0, l1, l2 = lengths[-1]  # the cap
    x = (l2 ** 2 + l1 ** 2 - l0 ** 2) / (2 * l2)
    P = np.array([[0.0, 0.0], [l2, 0.0], [x, np.sqrt(l1 ** 2 - x ** 2)]])
    dots = np.array([np.dot(P[(k + 1) % 3] - P[k], P[(k + 2) % 3] - P[k]) for k in range(3)])
    e1, e2 = P[1] - P[0], P[2] - P[0]
    planar_area = 0.5 * abs(e1[0] * e2[1] - e1[1] * e2[0])
    scale = area[-1] / planar_area  # corner_weights scales the mesh to area 4 pi
    np.testing.assert_allclose(lam[-1], 0.25 * scale * dots, rtol=1e-9)
    np.testing.assert_allclose(area.sum(), 4 * np.pi, rtol=1e-12)
    assert planar_area > 1e3 * 0.5 * igl.doublearea(V, F)[-1]  # thin, but no longer flat


def test_corner_weights_without_mollification_are_libigls_cotangents():
    """``a . b = 2 A cot theta``, so ``lam_k / A = cot(theta_k) / 2``: summed over the two faces
    of an edge, libigl's cotangent Laplacian entry."""
    V, F = icosphere(2)
    V = V * np.array([1.0, 2.0, 0.5])
    lam, area = corner_weights(V, F)
    C = igl.cotmatrix(V, F).toarray()  # C_ij = (cot a + cot b) / 2, i != j
    W = np.zeros_like(C)
    for k in range(3):
        j, l = F[:, (k + 1) % 3], F[:, (k + 2) % 3]
        np.add.at(W, (j, l), lam[:, k] / area)
        np.add.at(W, (l, j), lam[:, k] / area)
    np.fill_diagonal(C, 0.0)
    np.testing.assert_allclose(W, C, rtol=1e-9, atol=1e-12)

"""igl_spheremap.sphere.mobius: Möbius transformations of the sphere and Möbius normalization."""

import itertools

import igl
import numpy as np
import pytest

from igl_spheremap import count_folds, image_centroid, mobius_center, mobius_transform
from igl_spheremap.mesh.operators import vertex_areas


def _unit(X):
    return X / np.linalg.norm(X, axis=1, keepdims=True)


def _cross_ratios(X, quads):
    """Absolute cross ratios |x_a - x_b| |x_c - x_d| / (|x_a - x_c| |x_b - x_d|) (chordal)."""
    def d(i, j):
        return np.linalg.norm(X[i] - X[j], axis=1)

    a, b, c, e = quads.T
    return d(a, b) * d(c, e) / (d(a, c) * d(b, e))


def _complex_cross_ratios(X, quads):
    """Complex cross ratios of the stereographic projections from the north pole."""
    z = (X[:, 0] + 1j * X[:, 1]) / (1.0 - X[:, 2])
    a, b, c, e = (z[q] for q in quads.T)
    return (a - b) * (c - e) / ((a - e) * (c - b))


def test_transform_keeps_unit_norm_and_inverts(rng):
    U = _unit(rng.normal(size=(1000, 3)))
    for r in (0.1, 0.6, 0.95):
        c = r * _unit(rng.normal(size=(1, 3)))[0]
        Y = mobius_transform(U, c)
        assert np.abs(np.linalg.norm(Y, axis=1) - 1.0).max() <= 1e-15
        # The hyperbolic translations along one axis form a group: T_{-c} = T_c^{-1}.
        assert np.abs(mobius_transform(Y, -c) - U).max() < 1e-12 / (1.0 - r)
        # The two ends of the axis are fixed; points move away from c/|c|.
        ends = np.array([c, -c]) / r
        assert np.abs(mobius_transform(ends, c) - ends).max() < 1e-14
        assert np.all(Y @ c <= U @ c + 1e-15)


def test_transform_preserves_cross_ratios_and_orientation(rng):
    U = _unit(rng.normal(size=(60, 3)))
    U = U[U[:, 2] < 0.8]  # keep away from the projection pole
    quads = np.array(list(itertools.combinations(range(12), 4)))
    c = np.array([0.35, -0.2, 0.5])
    Y = mobius_transform(U, c)
    Y_pole_safe = Y[:, 2] < 0.95
    assert np.allclose(_cross_ratios(Y, quads), _cross_ratios(U, quads), rtol=1e-11, atol=0)
    q = quads[Y_pole_safe[quads].all(axis=1)]
    assert len(q) > 100
    # Complex cross ratio preserved (not conjugated): a Möbius, not an anti-Möbius, map.
    assert np.allclose(_complex_cross_ratios(Y, q), _complex_cross_ratios(U, q), rtol=1e-9)
    # A radial re-projection from c is not conformal: it changes cross ratios.
    radial = _unit(U - c)
    assert not np.allclose(_cross_ratios(radial, quads), _cross_ratios(U, quads), rtol=1e-3)


def test_transform_maps_circles_to_circles(rng):
    n = _unit(np.array([[0.2, 0.7, -0.4]]))[0]
    e1 = _unit(np.cross(n, [1.0, 0.0, 0.0])[None])[0]
    e2 = np.cross(n, e1)
    t = np.linspace(0.0, 2.0 * np.pi, 40, endpoint=False)
    h = 0.3  # the circle {x : x . n = h} on the unit sphere
    X = h * n + np.sqrt(1.0 - h * h) * (np.outer(np.cos(t), e1) + np.outer(np.sin(t), e2))
    for c in (np.array([0.5, 0.1, 0.2]), np.array([-0.1, -0.7, 0.3])):
        Y = mobius_transform(X, c)
        s = np.linalg.svd(Y - Y.mean(axis=0), compute_uv=False)
        assert s[2] < 1e-12 * s[0]  # coplanar: a circle on the sphere


def test_transform_keeps_the_sphere_map_fold_free(icosphere):
    V, F = icosphere(3)
    for c in ([0.5, 0.0, 0.0], [0.3, -0.4, 0.6]):
        assert count_folds(F, mobius_transform(V, np.array(c))) == 0


def test_transform_rejects_centers_outside_the_ball(rng):
    U = _unit(rng.normal(size=(10, 3)))
    with pytest.raises(ValueError, match="inside the unit ball"):
        mobius_transform(U, np.array([0.6, 0.8, 0.0]))
    # a 2-vector or 2 columns: a numpy broadcast error before
    with pytest.raises(ValueError, match=r"U of shape \(n, 3\) and c of shape \(3,\)"):
        mobius_transform(U, [0.1, 0.0])
    with pytest.raises(ValueError, match=r"got \(10, 2\)"):
        mobius_transform(U[:, :2], [0.1, 0.0, 0.0])


def test_transform_refuses_rows_off_the_unit_sphere(rng):
    """A FreeSurfer ``?h.sphere`` (radius 100) or a NaN row: directions that are no Möbius
    image (the formula holds on the unit sphere only), returned without a word before."""
    U = _unit(rng.normal(size=(50, 3)))
    c = np.array([0.2, 0.0, 0.1])
    with pytest.raises(ValueError, match=r"U has 50 rows off the unit sphere .* = 99"):
        mobius_transform(100.0 * U, c)
    bad = U.copy()
    bad[7] *= 1.001
    with pytest.raises(ValueError, match="U has 1 row off the unit sphere"):
        mobius_transform(bad, c)
    bad[7] = np.nan
    with pytest.raises(ValueError, match="U has 1 row with NaN"):
        mobius_transform(bad, c)
    # float32 storage rounding is accepted
    Y = mobius_transform(U.astype(np.float32), c)
    assert np.abs(Y - mobius_transform(U, c)).max() < 1e-6


def test_center_refuses_weights_and_maps_it_cannot_center(rng):
    """Negative, NaN, all-zero or short weights, and NaN rows: accepted, or a message about the
    Möbius centre (|c| = nan) or a matmul error, before."""
    U = _unit(rng.normal(size=(10, 3)))
    w = np.ones(10)
    for bad, what in ((-w, "weights has 10 values that are not finite, at least 0"),
                      (0.0 * w, "weights sums to 0"),
                      (np.r_[np.nan, w[1:]], "weights has 1 value that is not finite"),
                      (w[:-3], r"one weight per vertex \(10\)")):
        with pytest.raises(ValueError, match=what):
            mobius_center(U, bad)
    with pytest.raises(ValueError, match="1 row with NaN"):
        mobius_center(np.r_[[[np.nan] * 3], U[1:]], w)


def test_center_brings_the_centroid_to_zero_by_a_true_mobius_map(icosphere, fit_rotation):
    """Centered Möbius normalizations are unique up to rotation, so centering a Möbius
    image of the (centered) icosphere gives back a rotation of the icosphere."""
    V, F = icosphere(3)
    w = vertex_areas(V, F)
    c = np.array([0.4, -0.3, 0.35])
    U = mobius_transform(V, c)
    assert np.linalg.norm(w @ U) / w.sum() > 0.3
    C, mu = mobius_center(U, w)
    centroid = np.linalg.norm(w @ C) / w.sum()
    assert centroid < 1e-10 and mu == pytest.approx(centroid, abs=1e-15)
    assert np.linalg.norm(image_centroid(V, F, C)) < 1e-10
    quads = np.random.default_rng(3).integers(0, V.shape[0], size=(500, 4))
    quads = quads[np.array([len(set(q)) == 4 for q in quads])]
    assert np.allclose(_cross_ratios(C, quads), _cross_ratios(U, quads), rtol=1e-9, atol=0)
    Q, residual = fit_rotation(V, C)
    assert np.linalg.det(Q) > 0 and residual < 1e-9
    assert count_folds(F, C) == 0


def test_center_of_a_real_map(conformal_map):
    V, F, result, _ = conformal_map("fish_lowres.obj")
    w = vertex_areas(V, F)
    U = mobius_transform(result.U, np.array([0.0, 0.5, -0.3]))
    C, _ = mobius_center(U, w)
    assert np.linalg.norm(w @ C) / w.sum() < 1e-10
    assert count_folds(F, C) == 0
    assert np.abs(np.linalg.norm(C, axis=1) - 1.0).max() < 1e-14


def test_center_leaves_a_centered_map_unchanged(icosphere):
    V, F = icosphere(2)
    C, mu = mobius_center(V, vertex_areas(V, F))
    assert mu < 1e-12 and np.array_equal(C, V)


def test_center_of_a_map_with_all_weight_at_one_point(icosphere):
    """A map crowded below rounding (the lifted Tutte disk of a long shape) can put all the
    weight at one point: the Jacobian ``2 (I - sum w U U^T)`` is then exactly singular.  The
    step goes along the centroid; the Möbius maps along it fix that point and its antipode
    and move every other point away from it, so the unweighted points' distance from it
    grows and the weighted ones stay put."""
    V, _ = icosphere(2)
    north = np.array([0.0, 0.0, 1.0])
    top = np.isclose(V @ north, 1.0)
    U = V.copy()
    U[top] = north
    w = top.astype(float)  # the weight of the top vertex only: sum w U U^T = diag(0, 0, 1)
    C, mu = mobius_center(U, w)
    assert np.isclose(mu, 1.0)  # identical points stay identical: no centering possible
    assert np.array_equal(C[top], U[top])
    rest = ~top & ~np.isclose(V @ north, -1.0)
    assert np.all(C[rest] @ north < U[rest] @ north)
    assert np.abs(np.linalg.norm(C, axis=1) - 1.0).max() < 1e-14


def _random_rotation(rng):
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return Q * np.sign(np.linalg.det(Q))


@pytest.mark.parametrize("k", [3, 4, 8])
def test_fit_recovers_a_known_mobius_transformation(rng, k):
    from igl_spheremap.sphere.mobius import mobius_fit

    P = _unit(rng.normal(size=(k, 3)))
    c0 = 0.7 * _unit(rng.normal(size=(1, 3)))[0]
    R0 = _random_rotation(rng)
    Q = mobius_transform(P, c0) @ R0.T
    c, R, residual = mobius_fit(P, Q)
    assert residual < 1e-12
    np.testing.assert_allclose(mobius_transform(P, c) @ R.T, Q, atol=1e-12)
    if k >= 4:  # more than three points in general position fix the transformation
        np.testing.assert_allclose(c, c0, atol=1e-10)
        np.testing.assert_allclose(R, R0, atol=1e-10)


def test_fit_of_inexact_pairs_is_a_local_minimum_below_the_best_rotation(rng):
    from igl_spheremap.sphere.mobius import (ball_point as _ball_point, best_rotation as _best_rotation, mobius_fit)

    def cost(c):
        X = mobius_transform(P, c)
        return np.sqrt(np.mean(np.sum((X @ _best_rotation(X, Q).T - Q) ** 2, axis=1)))

    P = _unit(rng.normal(size=(8, 3)))
    Q = _unit(mobius_transform(P, np.array([0.3, -0.2, 0.1])) + 0.1 * rng.normal(size=(8, 3)))
    c, R, residual = mobius_fit(P, Q)
    assert residual == pytest.approx(cost(c), rel=1e-12)
    assert residual < cost(np.zeros(3))  # better than the rotation alone
    z = np.arctanh(np.linalg.norm(c)) * c / np.linalg.norm(c)
    for d in 1e-4 * _unit(rng.normal(size=(50, 3))):
        assert cost(_ball_point(z + d)) >= residual - 1e-14


def test_a_dilation_moves_each_point_along_its_great_circle_by_the_stereographic_law():
    """``dilation(U, c, f)``: the angle from ``c`` goes to ``2 atan(f tan(theta / 2))``, the
    azimuth about ``c`` is kept, the dilation by ``1 / f`` undoes it, and a cluster crowded
    to 1e-12 around ``c`` is spread by the same law to six digits (from its offsets to ``c``:
    dot products would round them away)."""
    from igl_spheremap.sphere.geodesics import angles
    from igl_spheremap.sphere.mobius import dilation
    rng = np.random.default_rng(3)
    U = rng.normal(size=(500, 3))
    U /= np.linalg.norm(U, axis=1, keepdims=True)
    c = U[0]
    U = U[U @ c > -0.9]  # away from -c, where the projection is singular
    Z = dilation(U, c, 7.0)
    theta = angles(U, np.tile(c, (len(U), 1)))
    np.testing.assert_allclose(angles(Z, np.tile(c, (len(U), 1))),
                               2 * np.arctan(7.0 * np.tan(theta / 2)), atol=1e-12)
    planes = np.einsum("ij,ij->i", np.cross(c, U), Z)  # Z in the plane of c and U
    assert np.abs(planes).max() < 1e-12
    np.testing.assert_allclose(dilation(Z, c, 1 / 7.0), U, atol=1e-12)
    X = c + 1e-12 * rng.normal(size=(50, 3))  # a cluster crowded to 1e-12 around c
    X /= np.linalg.norm(X, axis=1, keepdims=True)
    theta = 2 * np.arcsin(np.linalg.norm(X - c, axis=1) / 2)  # from chords: exact here
    np.testing.assert_allclose(angles(dilation(X, c, 1e12), np.tile(c, (len(X), 1))),
                               2 * np.arctan(1e12 * np.tan(theta / 2)), rtol=1e-6)


@pytest.mark.parametrize("factor", [0.0, -2.0, np.inf, np.nan])
def test_a_dilation_refuses_a_factor_that_is_not_positive_and_finite(factor):
    from igl_spheremap.sphere.mobius import dilation
    with pytest.raises(ValueError, match="positive and finite"):
        dilation(np.eye(3), np.array([0.0, 0.0, 1.0]), factor)


def test_center_accepts_a_list_and_gives_the_array_result(icosphere):
    """``U`` as a list of rows: AttributeError 'list' object has no attribute 'T' before
    (weights as a list were accepted)."""
    V, F = icosphere(2)
    U = mobius_transform(V, np.array([0.3, -0.1, 0.2]))
    w = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_VORONOI).diagonal()
    W, mu = mobius_center(U.tolist(), w.tolist())
    W0, mu0 = mobius_center(U, w)
    assert np.array_equal(W, W0) and mu == mu0
    assert np.linalg.norm(w @ W) / w.sum() < 1e-12

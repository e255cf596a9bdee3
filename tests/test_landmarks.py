"""igl_spheremap.landmark_map: landmark-matched spherical maps (hard and soft), and their refusals."""

import igl
import numpy as np
import pytest

import igl_spheremap as sm
from igl_spheremap import MeshError, SphericalMapWarning, landmark_map


def _det_folds(F, U):
    return int(np.count_nonzero(np.linalg.det(np.stack([U[F[:, k]] for k in range(3)], 1)) <= 0))


def _angle_deg(U, Q):
    """Angle between rows, degrees (atan2 of |u x q| and u . q: exact near 0)."""
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(U, Q), axis=1), np.sum(U * Q, axis=1)))


def _smooth_targets(P, amplitude, seed):
    """P moved by a smooth (low-frequency) field: landmark order is kept."""
    r = np.random.default_rng(seed)
    A, b = r.normal(size=(3, 3)), r.normal(size=3)
    Q = P + amplitude * np.sin(2.0 * P @ A + b)
    return Q / np.linalg.norm(Q, axis=1, keepdims=True)


@pytest.fixture(scope="module")
def ellipsoid_map():
    from conftest import make_ellipsoid
    V, F = make_ellipsoid(3, (1.0, 1.4, 2.2))
    return V, F, sm.spherical_conformal_map(V, F)


def test_hard_landmarks_are_on_their_targets_and_fold_free(ellipsoid_map):
    V, F, base = ellipsoid_map
    lm = np.array([3, 40, 77, 150, 301, 555])
    Q = _smooth_targets(base.U[lm], 0.08, seed=1)
    res = landmark_map(V, F, lm, Q)
    assert res.success, res.message
    assert _angle_deg(res.U[lm], Q).max() <= np.degrees(1e-12)
    assert np.allclose(res.landmark_errors, _angle_deg(res.U[lm], Q), atol=1e-12)
    assert _det_folds(F, res.U) == 0 == res.folds
    assert [r.kind for r in res.rounds][-1] == "landmark"
    # the rest minimizes the harmonic energy (modulo the infinitesimal Möbius dilations,
    # along which the discrete energy is not invariant): the RMS gradient over the other
    # vertices, projected off the dilation fields by least squares, recomputed here
    if res.rounds[-1].frozen == 0:
        L = igl.intrinsic_delaunay_cotmatrix(V, F)[0]
        a = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_BARYCENTRIC).diagonal()
        a = a * (4 * np.pi / a.sum())
        U = res.U
        H = -(L @ U) / a[:, None]
        G = H - np.sum(H * U, axis=1)[:, None] * U
        free = np.ones(len(V), bool)
        free[lm] = False
        Z = np.stack([np.eye(3)[k] - U[:, [k]] * U for k in range(3)], axis=2)[free]
        w = np.sqrt(a[free])[:, None]
        lam = np.linalg.lstsq((Z * w[:, :, None]).reshape(-1, 3), (G[free] * w).ravel(),
                              rcond=None)[0]
        P = G[free] - Z @ lam
        assert np.sqrt(a[free] @ np.sum(P * P, axis=1) / (4 * np.pi)) <= 1e-5


def test_targets_at_the_conformal_positions_leave_the_map_unchanged(ellipsoid_map):
    V, F, base = ellipsoid_map
    lm = np.array([0, 10, 200, 400])
    res = landmark_map(V, F, lm, base.U[lm])
    assert res.success
    assert np.abs(res.U - base.U).max() < 1e-9


def test_soft_landmark_error_falls_as_the_weight_grows(ellipsoid_map):
    V, F, base = ellipsoid_map
    lm = np.array([3, 40, 77, 150, 301, 555])
    Q = _smooth_targets(base.U[lm], 0.08, seed=1)
    errors = []
    for weight in (0.3, 3.0, 30.0):
        res = landmark_map(V, F, lm, Q, mode="soft", weight=weight)
        assert res.success and _det_folds(F, res.U) == 0
        errors.append(_angle_deg(res.U[lm], Q).mean())
    assert errors[0] > errors[1] > errors[2] > 0


def test_swapped_landmarks_are_reported_not_folded(ellipsoid_map):
    """Two landmarks asked to trade places would collide on the way: an honest failure,
    with a fold-free map."""
    V, F, base = ellipsoid_map
    lm = np.array([0, 300, 555, 601])
    Q = base.U[lm].copy()
    Q[[0, 1]] = Q[[1, 0]]
    with pytest.warns(SphericalMapWarning, match="cannot be reached without folds"):
        res = landmark_map(V, F, lm, Q)
    assert not res.success and "cannot be reached without folds" in res.message
    assert _det_folds(F, res.U) == 0


@pytest.mark.parametrize("landmarks, targets, message", [
    ([], np.zeros((0, 3)), "at least 1 landmark"),
    ([1, 1, 2], None, "1 duplicate landmark"),
    ([1, 2, 700], None, "1 landmark indices outside 0..641"),
    ([1.0, 2.0], None, "integer vertex indices"),
    ([1, 2], "nan", "1 rows with NaN"),
    ([1, 2], "short", "2 landmarks but 1 targets"),
    ([1, 2], "off", "1 targets are not on the unit sphere"),
    ([1, 2, 3], "same", "1 pairs of landmarks with the same target"),
])
def test_bad_landmarks_and_targets_are_value_errors(ellipsoid_map, landmarks, targets, message):
    V, F, base = ellipsoid_map
    lm = np.asarray(landmarks)
    Q = base.U[np.asarray(landmarks, dtype=np.int64) % len(V)] if targets is None else targets
    if isinstance(targets, str):
        Q = base.U[lm].copy()
        if targets == "nan":
            Q[0, 1] = np.nan
        elif targets == "short":
            Q = Q[:1]
        elif targets == "off":
            Q[1] *= 1.01
        elif targets == "same":
            Q[2] = Q[0]
    with pytest.raises(ValueError, match=message):
        landmark_map(V, F, lm, Q)


def test_a_face_with_mirrored_landmark_targets_is_refused(ellipsoid_map):
    V, F, base = ellipsoid_map
    face = F[10]
    Q = base.U[face][[0, 2, 1]]  # the same three points, in the opposite orientation
    with pytest.raises(ValueError, match="1 faces have all three vertices as landmarks"):
        landmark_map(V, F, face, Q)


def test_other_bad_arguments(ellipsoid_map):
    V, F, base = ellipsoid_map
    lm = np.array([1, 2, 3])
    with pytest.raises(ValueError, match="unknown mode"):
        landmark_map(V, F, lm, base.U[lm], mode="firm")
    with pytest.raises(ValueError, match="weight applies to mode='soft' only"):
        landmark_map(V, F, lm, base.U[lm], weight=3.0)
    with pytest.raises(ValueError, match="weight must be"):
        landmark_map(V, F, lm, base.U[lm], mode="soft", weight=-1.0)
    with pytest.raises(MeshError):
        landmark_map(V, F[1:], lm, base.U[lm])
    V2 = np.vstack([V, [[5.0, 5.0, 5.0]]])
    with pytest.raises(ValueError, match="1 landmarks are vertices used by no face"):
        landmark_map(V2, F, [len(V)], base.U[:1])


def test_a_nearly_flat_image_triangle_flipped_by_a_step_is_untangled_around_the_landmarks():
    # An icosphere with one extra vertex 1e-6 from an edge inside its face:
    # the face (a, b, m) is nearly flat on the sphere, and any smooth
    # deformation curved over it carries m across (a, b).
    from igl_spheremap.landmark_steps import deform, deformed

    V, F = sm.icosphere(3)
    a, b, c = F[0]
    h = 1e-6
    m = (0.5 - h) * (V[a] + V[b]) + 2 * h * V[c]
    U = np.vstack([V, m / np.linalg.norm(m)])
    G = np.vstack([F[1:], [[a, b, len(V)], [b, c, len(V)], [c, a, len(V)]]])
    assert _det_folds(G, U) == 0
    lm = np.array([F[5][0], 100])
    axis = np.cross(U[lm[0]], U[c])
    axis /= np.linalg.norm(axis)
    t = np.radians(3.0)
    Q = np.vstack([np.cos(t) * U[lm[0]] + np.sin(t) * np.cross(axis, U[lm[0]]), U[100]])
    assert _det_folds(G, deform(U, U[lm], Q, lm)) == 1  # the raw deformation flips the sliver

    Y, reached = deformed(G, U, lm, Q)

    assert reached == 1.0
    assert _det_folds(G, Y) == 0
    np.testing.assert_array_equal(Y[lm], Q)
    np.testing.assert_allclose(np.linalg.norm(Y, axis=1), 1.0, atol=1e-12)

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
        res = landmark_map(V, F, lm, Q, mode="soft", weight=weight, landmark_tol=10.0)
        assert res.success and _det_folds(F, res.U) == 0
        errors.append(_angle_deg(res.U[lm], Q).mean())
    assert errors[0] > errors[1] > errors[2] > 0


def test_soft_landmarks_succeed_exactly_within_their_tolerance(ellipsoid_map):
    """Soft landmarks 60 degrees from their targets (weight 0.3, targets 19 degrees away) were
    a success, no warning, "near their targets"."""
    V, F, base = ellipsoid_map
    lm = np.array([3, 40, 77, 150, 301, 555])
    Q = _smooth_targets(base.U[lm], 0.3, seed=1)
    with pytest.warns(SphericalMapWarning, match=r"landmarks farther than landmark_tol = 2 deg"):
        loose = landmark_map(V, F, lm, Q, mode="soft", weight=0.3)
    err = _angle_deg(loose.U[lm], Q)
    assert not loose.success and _det_folds(F, loose.U) == 0
    assert f"{int((err > 2.0).sum())} of 6 landmarks" in loose.message
    np.testing.assert_allclose(loose.landmark_errors, err, atol=1e-9)
    firm = landmark_map(V, F, lm, Q, mode="soft", weight=100.0, landmark_tol=2.0)
    err = _angle_deg(firm.U[lm], Q)
    assert firm.success == (err.max() <= 2.0) and firm.success, err


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
    ([2, 1, 1], None, r"1 duplicate landmark index \(first: vertex 1 at positions \[1, 2\]"),
    ([1, 2, 700], None, "1 landmark index outside 0..641"),
    ([1.0, 2.0], None, "integer vertex indices"),
    ([1, 2], "nan", "1 row with NaN"),
    ([1, 2], "short", "2 landmarks but 1 target"),
    ([1, 2], "off", "1 target is not on the unit sphere"),
    ([1, 2, 3], "same", "1 pair of landmarks with the same target"),
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
    with pytest.raises(ValueError, match="1 face has all three vertices as landmarks"):
        landmark_map(V, F, face, Q)


def test_other_bad_arguments(ellipsoid_map):
    V, F, base = ellipsoid_map
    lm = np.array([1, 2, 3])
    with pytest.raises(ValueError, match="unknown mode"):
        landmark_map(V, F, lm, base.U[lm], mode="firm")
    with pytest.raises(ValueError, match="weight and landmark_tol apply to mode='soft' only"):
        landmark_map(V, F, lm, base.U[lm], weight=3.0)
    with pytest.raises(ValueError, match="weight and landmark_tol apply to mode='soft' only"):
        landmark_map(V, F, lm, base.U[lm], landmark_tol=1.0)
    with pytest.raises(ValueError, match="landmark_tol must be"):
        landmark_map(V, F, lm, base.U[lm], mode="soft", landmark_tol=0.0)
    with pytest.raises(ValueError, match="weight must be"):
        landmark_map(V, F, lm, base.U[lm], mode="soft", weight=-1.0)
    with pytest.raises(MeshError):
        landmark_map(V, F[1:], lm, base.U[lm])
    V2 = np.vstack([V, [[5.0, 5.0, 5.0]]])
    with pytest.raises(ValueError, match="1 landmark is a vertex used by no face"):
        landmark_map(V2, F, [len(V)], base.U[:1])


def test_a_nearly_flat_image_triangle_flipped_by_a_step_is_untangled_around_the_landmarks():
    # An icosphere with one extra vertex 1e-6 from an edge inside its face:
    # the face (a, b, m) is nearly flat on the sphere, and any smooth
    # deformation curved over it carries m across (a, b).
    from igl_spheremap.uses.spline import deform
    from igl_spheremap.uses.landmarks import deformed

    V, F = sm.icosphere(3)
    a, b, c = F[0]
    h = 1e-6
    m = (0.5 - h) * (V[a] + V[b]) + 2 * h * V[c]
    U = np.vstack([V, m / np.linalg.norm(m)])
    G = np.vstack([F[1:], [[a, b, len(V)], [b, c, len(V)], [c, a, len(V)]]])
    assert _det_folds(G, U) == 0
    # three landmarks near the sliver, the first turned by 5 degrees toward a, the
    # others fixed (vertex numbers of icosphere(3))
    lm = np.array([270, 245, 163])
    axis = np.cross(U[lm[0]], U[a])
    axis /= np.linalg.norm(axis)
    t = np.radians(5.0)
    Q = U[lm].copy()
    Q[0] = np.cos(t) * U[lm[0]] + np.sin(t) * np.cross(axis, U[lm[0]])
    assert _det_folds(G, deform(U, U[lm], Q, lm)) == 1  # the raw deformation flips the sliver

    Y, reached = deformed(G, U, lm, Q)

    assert reached == 1.0
    assert _det_folds(G, Y) == 0
    np.testing.assert_array_equal(Y[lm], Q)
    np.testing.assert_allclose(np.linalg.norm(Y, axis=1), 1.0, atol=1e-12)


def test_a_close_landmark_pair_pulled_apart_reaches_its_targets(conformal_map):
    """Two landmark images 0.002-0.004 apart with targets 8x further apart, and
    moves up to ~15 degrees: a single-width Gaussian deformation is too ill-conditioned
    (it missed the landmarks by more than their image triangles and failed)."""
    V, F, base, _ = conformal_map("hippocampus.obj")
    U = base.U
    # 12 landmarks spread by farthest-point sampling, and a 13th whose image is
    # 0.002-0.004 from the first one's (as on the hippocampus registration pair)
    far = [int(np.argmax(V[:, 0]))]
    for _ in range(11):
        far.append(int(np.argmax(np.linalg.norm(V[:, None] - V[far][None], axis=2).min(1))))
    for first in far:
        d = np.linalg.norm(U - U[first], axis=1)
        near = np.flatnonzero((d > 0.002) & (d < 0.004))
        if near.size:
            break
    far.remove(first)
    lm = np.array([first] + far + [int(near[0])])
    Q = _smooth_targets(U[lm], 0.25, seed=3)
    # the pair's targets 8x further apart than its images, around their midpoint
    mid, half = 0.5 * (Q[0] + Q[-1]), 4.0 * (U[lm[-1]] - U[lm[0]])
    Q[0], Q[-1] = mid - half, mid + half
    Q /= np.linalg.norm(Q, axis=1, keepdims=True)
    res = landmark_map(V, F, lm, Q)
    assert res.success, res.message
    assert _angle_deg(res.U[lm], Q).max() <= np.degrees(1e-12)
    assert _det_folds(F, res.U) == 0


def test_a_landmark_star_below_the_rounding_of_positions_moves_as_a_whole():
    """A leg tip of a conformal map: the landmark's image star spans 1e-14 (about 90 units in the last place of its coordinates).  The
    deformation must carry it by its differential (area ratios of the star's
    faces all equal to first order), not by per-vertex rounding noise."""
    from igl_spheremap.uses.spline import deform
    from igl_spheremap.uses.landmarks import deformed
    V, F = sm.icosphere(3)
    v = 7
    star = np.flatnonzero((F == v).any(axis=1))
    ring = np.setdiff1d(np.unique(F[star]), [v])
    U = V.copy()
    U[ring] = V[v] + 1e-14 * (V[ring] - V[v])
    U /= np.linalg.norm(U, axis=1, keepdims=True)
    assert _det_folds(F, U) == 0
    lm = np.array([v, 60, 100, 200, 300, 400, 500, 600, 640, 30, 250, 350])
    Q = _smooth_targets(U[lm], 0.25, seed=5)

    def dets(X):  # signed volumes from edge vectors (exact differences of close points)
        a, b, c = (X[F[star, k]] for k in range(3))
        return np.einsum("ij,ij->i", np.cross(b - a, c - a), a)

    ratio = dets(deform(U, U[lm], Q, lm)) / dets(U)
    assert ratio.min() > 0
    # a linear map scales every area by the same factor; rounding the positions
    # to 1.1e-16 leaves a few percent here (without the linearization: 137 %)
    assert ratio.max() / ratio.min() - 1 < 0.25
    Y, reached = deformed(F, U, lm, Q)
    assert reached == 1.0
    assert _det_folds(F, Y) == 0
    np.testing.assert_array_equal(Y[lm], Q)


def test_four_landmarks_reach_targets_of_a_smooth_fold_free_deformation(conformal_map):
    """k = 4: the linear polynomials alone interpolate 4 displacements, so a
    thin-plate spline with them is affine and stretches the whole sphere (here:
    folds 58 % of the way); with the constant alone (tried first) the targets
    are reached."""
    V, F, base, _ = conformal_map("hippocampus.obj")
    far = [int(np.argmax(np.linalg.norm(V - V.mean(axis=0), axis=1)))]
    for _ in range(3):
        far.append(int(np.argmax(np.linalg.norm(V[:, None] - V[far][None], axis=2).min(1))))
    lm = np.array(far)
    # the targets are where a smooth fold-free deformation of the whole map puts
    # the landmarks, so a fold-free map reaching them exists
    W = _smooth_targets(base.U, 0.3, seed=24)
    assert _det_folds(F, W) == 0
    Q = W[lm]
    res = landmark_map(V, F, lm, Q)
    assert res.success, res.message
    assert _angle_deg(res.U[lm], Q).max() <= np.degrees(1e-12)
    assert _det_folds(F, res.U) == 0


@pytest.mark.parametrize("k", [1, 2, 3, 4, 5, 8])
def test_the_spline_interpolates_the_displacements_for_any_landmark_count(k):
    from igl_spheremap.uses.spline import spline_field
    r = np.random.default_rng(k)
    A = r.normal(size=(k, 3))
    A /= np.linalg.norm(A, axis=1, keepdims=True)
    D = 0.1 * r.normal(size=(k, 3))
    np.testing.assert_allclose(spline_field(A, D)(A), D, atol=1e-12)


def test_with_four_landmarks_the_affine_spline_is_tried_when_the_constant_one_fails(monkeypatch):
    """(The bimba registration pair with k = 4: the constant spline folds 7 % of
    the way, the affine one reaches the targets.)"""
    import igl_spheremap.uses.landmarks as steps
    calls = []

    def fake(F, U, lm, Q, linear, *rest):
        calls.append(linear)
        return np.full_like(U, float(linear)), (1.0 if linear else 0.07)
    monkeypatch.setattr(steps, "_steps", fake)
    U = np.zeros((10, 3))
    Y, t = steps.deformed(None, U, np.arange(4), None)
    assert calls == [False, True] and t == 1.0 and (Y == 1.0).all()
    calls.clear()
    steps.deformed(None, U, np.arange(5), None)
    assert calls == [True]

"""Atlas registration: the energies' gradients against finite differences, a known rotation and a
known smooth deformation recovered, fold-free as float32, the result's verdicts."""

import warnings

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from igl_spheremap import SphericalMapWarning, icosphere
from igl_spheremap.mesh.operators import laplacian, to_sphere_area, vertex_areas
from igl_spheremap.optimize.matching import FeatureMatchEnergy, PointMatchEnergy
from igl_spheremap.sphere.field import SphereField
from igl_spheremap.sphere.folds import count_folds, folds_after_rounding
from igl_spheremap.uses.atlas import (DEFAULT_LEVELS, Level, feature_schedule, register_sphere,
                                      start_warnings)
from igl_spheremap.uses.atlas_multires import register_sphere_multires
from igl_spheremap.sphere.harmonics import rotation_angle
from igl_spheremap.uses.rigid import rigid_align

from test_sphere_field import bumps


def angles(A, B):
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(A, B), axis=1), (A * B).sum(1)))


def deformed(V, F, degrees=8.0, seed=7):
    """``V`` moved along the gradient of a smooth function, ``degrees`` at most (fold-free)."""
    _, grad, _ = SphereField(V, F, bumps(V, seed=seed, width=0.8))(V)
    U = V + np.radians(degrees) * grad[:, 0] / np.abs(grad[:, 0]).max()
    U /= np.linalg.norm(U, axis=1, keepdims=True)
    assert count_folds(F, U) == 0
    return U


@pytest.fixture(scope="module")
def sphere():
    V, F = icosphere(4)
    return V, F, bumps(V, k=80, width=0.25)


def fd_check(E, U, rng, h=1e-6):
    G = E.euclidean_gradient(E.evaluate(U))
    D = rng.normal(size=U.shape)
    fd = (E.evaluate(U + h * D).value - E.evaluate(U - h * D).value) / (2 * h)
    assert fd == pytest.approx(float(np.vdot(G, D)), rel=1e-5)


def test_matching_energies_gradients_are_the_derivatives_of_their_values(sphere):
    V, F, f = sphere
    rng = np.random.default_rng(1)
    U = V + 0.02 * rng.normal(size=V.shape)
    U /= np.linalg.norm(U, axis=1, keepdims=True)
    area, L0 = to_sphere_area(vertex_areas(V, F)), laplacian(V, F, "cotan")
    fd_check(FeatureMatchEnergy(SphereField(V, F, np.c_[f, f ** 2]), np.c_[bumps(V, 4), f], area,
                                L0, 10.0, 0.5, 0.1, feature_weights=(1.0, 0.5)), U, rng)
    fd_check(PointMatchEnergy(V, area, L0, 100.0, 0.1), U, rng)


def test_rigid_align_recovers_a_known_rotation_and_flags_the_mirror(sphere):
    V, F, f = sphere
    R_true = Rotation.from_quat([0.3, -0.5, 0.6, 0.55]).as_matrix()  # scipy normalizes
    R, c, cm = rigid_align(V @ R_true.T, F, f, V, F, f)  # vertex i sits at R V_i, belongs at V_i
    assert np.degrees(rotation_angle(R @ R_true)) < 1.0
    assert c > 0.99 and cm < c - 0.1


def test_register_sphere_recovers_a_known_smooth_deformation(sphere):
    V, F, f = sphere
    U = deformed(V, F)
    levels = [replace_iter(lv, 60) for lv in DEFAULT_LEVELS]
    res = register_sphere(100.0 * U, F, f, 100.0 * V, F, f, levels=levels, rigid=False)
    before, after = angles(U, V), angles(res.U, V)
    assert before.mean() > 3.0
    assert after.mean() < 0.2 * before.mean()
    assert np.percentile(after, 90) < 1.0  # degrees; the vertex spacing is about 4
    assert res.success and res.improved and not res.warnings
    assert res.folds == 0 and res.below_margin == 0 and res.precision == "float32"
    assert folds_after_rounding(F, res.U, 100.0) == 0
    assert [lv["fwhm"] for lv in res.levels] == [lv.fwhm for lv in DEFAULT_LEVELS]
    assert repr(res).startswith("AtlasRegistrationResult(success=True, ")


def replace_iter(level, n):
    from dataclasses import replace

    return replace(level, max_iter=n)


def test_multiresolution_registers_a_finer_subject_through_an_icosphere():
    V, F = icosphere(4)
    f = bumps(V, k=80, width=0.25)
    U = deformed(V, F)
    levels = [replace_iter(lv, 40) for lv in DEFAULT_LEVELS]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SphericalMapWarning)
        res = register_sphere_multires(U, F, f, V, F, f, levels=levels, coarse_level=3,
                                       polish_iter=40)
    assert angles(res.U, V).mean() < 0.35 * angles(U, V).mean()
    assert res.folds == 0 and folds_after_rounding(F, res.U, 100.0) == 0
    assert [lv["stage"] for lv in res.levels] == ["coarse"] * 5 + ["full"]


def test_feature_schedule_adds_later_features_at_finer_levels():
    sched = feature_schedule(2)
    assert [lv.feature_weights for lv in sched] == [(1.0, 0.0), (1.0, 0.0), (1.0, 1.0),
                                                    (1.0, 1.0), (1.0, 1.0)]
    assert feature_schedule(1)[0].feature_weights == (1.0,)
    kept = feature_schedule(2, [Level(10.0, 10.0, feature_weights=(0.0, 1.0))])
    assert kept[0].feature_weights == (0.0, 1.0)


def test_a_poor_start_or_a_mirror_is_no_success():
    assert start_warnings(None, 0.9, 0.5) == [] and start_warnings(0.2, 0.9, 0.5) == []
    assert "poor start" in start_warnings(0.6, 0.9, 0.5)[0]
    assert "mirrored" in start_warnings(0.2, 0.5, 0.9)[0]


def test_bad_inputs_are_refused(sphere):
    V, F, f = sphere
    with pytest.raises(ValueError, match="but 1 target feature;"):
        register_sphere(V, F, np.c_[f, f], V, F, f)
    with pytest.raises(ValueError, match="features"):
        register_sphere(V, F, f[:-1], V, F, f)
    with pytest.raises(ValueError, match=r"1 of the 2 columns of target_features are constant "
                                         r"\(first: column 1, value 1\)"):
        register_sphere(V, F, np.c_[f, f], V, F, np.c_[f, np.ones_like(f)])
    U = V.copy()
    U[F[0, 0]] = -U[F[0, 0]]
    with pytest.raises(ValueError, match="folded"):
        register_sphere(U, F, f, V, F, f)
    with pytest.raises(ValueError, match="precision"):
        register_sphere(V, F, f, V, F, f, fold_barrier=False)
    # a target whose central projection is fold-free but which is no sphere (an ellipsoid,
    # a surface passed for its ?h.sphere): every vertex off the median radius but the poles'
    with pytest.raises(ValueError, match=r"target sphere target_U is not a sphere: \d+ of"):
        register_sphere(V, F, f, V * [1.0, 1.0, 1e6], F, f)
    with pytest.raises(ValueError, match=r"subject's sphere U is not a sphere"):
        register_sphere(100.0 * V * [1.0, 1.3, 1.0], F, f, V, F, f)
    register_sphere(100.0 * V, F, f, V, F, f, levels=[])  # any radius, one for all vertices
    # weights outside [0, 1], NaN features, negative smoothing: each named (before: accepted,
    # a message blaming the shape, accepted)
    with pytest.raises(ValueError, match=r"vertex_weights has \d+ values that are not finite, at least 0 and "
                                         r"at most 1"):
        register_sphere(V, F, f, V, F, f, vertex_weights=2.0 * np.ones(len(V)), levels=[])
    with pytest.raises(ValueError, match="vertex_weights sums to 0: no vertex has weight"):
        register_sphere(V, F, f, V, F, f, vertex_weights=np.zeros(len(V)), levels=[])
    with pytest.raises(ValueError, match="target_weights must have one weight per vertex"):
        register_sphere(V, F, f, V, F, f, target_weights=np.ones(3), levels=[])
    with pytest.raises(ValueError, match="features has 1 row with NaN"):
        register_sphere(V, F, np.r_[np.nan, f[1:]], V, F, f)
    with pytest.raises(ValueError, match=r"got shape \(7,\)"):
        register_sphere(V, F, f[:7], V, F, f)
    with pytest.raises(ValueError, match="fwhm must be finite and >= 0"):
        Level(fwhm=-5.0, sigma=2.0)

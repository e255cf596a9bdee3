"""igl_spheremap.mobius_area_correction: the area-minimizing Möbius transformation of a map."""

import contextlib
import io

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from conftest import drag_past_neighbor
from igl_spheremap.errors import SphericalMapWarning
from igl_spheremap.mesh.shapes import icosphere
from igl_spheremap.sphere.quality import area_distortion
from igl_spheremap.sphere.folds import count_folds
from igl_spheremap.sphere.mobius import mobius_transform
from igl_spheremap.uses.area_correction import MobiusAreaCorrection, mobius_area_correction


def _mean_abs_log_area_ratio(V, F, U):
    """The objective, independently from metrics.area_distortion (finite terms)."""
    d = np.abs(area_distortion(V, F, U))
    return float(d[np.isfinite(d)].mean())


def test_known_mobius_transformation_is_undone(fit_rotation):
    V, F = icosphere(3)
    c0 = np.array([0.3, -0.2, 0.4])
    U = mobius_transform(V, c0)  # a conformal map of the sphere with large area distortion
    assert _mean_abs_log_area_ratio(V, F, U) > 0.5
    r = mobius_area_correction(V, F, U)
    assert isinstance(r, MobiusAreaCorrection)
    assert np.abs(area_distortion(V, F, r.U)).max() < 1e-6  # equiareal like the identity
    assert r.distortion == pytest.approx(_mean_abs_log_area_ratio(V, F, r.U), abs=1e-15)
    # T_c o T_c0 is a rotation exactly when T_c sends T_c0(0) = -c0 to 0: c = -c0.
    assert np.abs(r.c + c0).max() < 1e-5
    assert fit_rotation(r.U, V)[1] < 1e-5
    assert np.abs(mobius_transform(U, r.c) - r.U).max() < 1e-15
    assert r.folds == 0 and r.initial_distortion > r.distortion


def test_rotation_of_the_input_map_changes_nothing():
    V, F = icosphere(2)
    U = mobius_transform(V, np.array([0.1, 0.5, -0.2]))
    R = Rotation.from_rotvec([0.4, -1.0, 0.3]).as_matrix()
    r1 = mobius_area_correction(V, F, U)
    r2 = mobius_area_correction(V, F, U @ R.T)
    assert r2.distortion == pytest.approx(r1.distortion, abs=1e-6)
    assert np.abs(r2.c - R @ r1.c).max() < 1e-4


@pytest.mark.filterwarnings("ignore:scipy.optimize:DeprecationWarning")  # LaPy's disp option
def test_not_above_identity_and_lapy_on_a_real_map(conformal_map):
    V, F, result, _ = conformal_map("hippocampus.obj")
    U = result.U
    r = mobius_area_correction(V, F, U)
    ours = _mean_abs_log_area_ratio(V, F, r.U)
    assert ours == pytest.approx(r.distortion, rel=1e-12)
    assert ours <= _mean_abs_log_area_ratio(V, F, U) == pytest.approx(r.initial_distortion, rel=1e-12)
    assert ours < r.initial_distortion  # the conformal map is not the area optimum
    assert r.folds == 0 == count_folds(F, r.U)
    lapy = pytest.importorskip("lapy")
    from lapy.conformal import mobius_area_correction_spherical

    with contextlib.redirect_stdout(io.StringIO()):  # LaPy's optimizer prints its progress
        U_lapy, _ = mobius_area_correction_spherical(lapy.TriaMesh(V, F), U)
    assert ours <= _mean_abs_log_area_ratio(V, F, U_lapy) + 1e-12


def test_fold_guard_on_a_coarse_mesh(monkeypatch):
    # A coarse icosahedron with very unequal input areas: the best translation flips
    # large flat image triangles unless those points are refused.
    import igl_spheremap.uses.area_correction as module

    U, F = icosphere(0)
    V = U * np.exp(np.random.default_rng(0).normal(0.0, 1.5, size=(12, 1)))
    guarded = mobius_area_correction(V, F, U)
    assert guarded.folds == 0 == count_folds(F, guarded.U)
    assert guarded.distortion < guarded.initial_distortion
    with monkeypatch.context() as m:
        m.setattr(module, "count_below_margin", lambda F, U, u: 0)  # the guard's count
        unguarded = mobius_area_correction(V, F, U)
    assert count_folds(F, unguarded.U) > 0  # the guard was needed here
    assert unguarded.distortion < guarded.distortion


def test_folded_input_warns_and_adds_no_fold():
    V, F = icosphere(3)
    U = drag_past_neighbor(F, mobius_transform(V, np.array([0.0, 0.3, 0.3])), 7)
    folds = count_folds(F, U)
    assert folds > 0
    with pytest.warns(SphericalMapWarning, match="folded faces"):
        r = mobius_area_correction(V, F, U)
    assert 0 < r.folds <= folds and count_folds(F, r.U) == r.folds


def test_bad_inputs_are_refused():
    V, F = icosphere(1)
    cases = [
        ((V[:, :2], F, V), "V must be"),
        ((V, F, V[:-1]), "U must have the shape"),
        ((V, F[:, :2], V), "F must be"),
        ((V, F + 40, V), "outside"),
        ((np.where(np.arange(V.shape[0])[:, None] == 2, np.nan, V), F, V), "V has 1 row"),
        ((V, F, 1.1 * V), "off the unit sphere"),
    ]
    for args, msg in cases:
        with pytest.raises(ValueError, match=msg):
            mobius_area_correction(*args)


def test_a_float32_ready_map_stays_float32_ready(rng):
    """A map with every face above its float32 margin keeps that (numpy's own float32
    rounding at radius 100 folds nothing), while an unconstrained correction would bring
    crowded faces below the margin."""
    from igl_spheremap import spherical_conformal_map
    from igl_spheremap.sphere.folds import below_margin, folds_after_rounding

    V, F = icosphere(3)
    V = V * np.array([1.0, 1.0, 20.0])  # elongated: the conformal map crowds the tips
    U = spherical_conformal_map(V, F, precision="float32").U
    assert not below_margin(F, U, "float32").any()
    r = mobius_area_correction(V, F, U)
    assert not below_margin(F, r.U, "float32").any()
    assert folds_after_rounding(F, r.U, 100.0) == 0
    assert r.distortion <= r.initial_distortion

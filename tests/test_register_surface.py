"""register_surface: a subject registered from its surface alone recovers a known rotation of its
own sphere, and a given sphere is used as it is."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from conftest import load_mesh
from igl_spheremap import register_surface, spherical_conformal_map
from igl_spheremap.uses import atlas_multires


@pytest.fixture(scope="module")
def subject():
    """The hippocampus, two smooth features of its surface, and its area-balanced sphere."""
    V, F = load_mesh("hippocampus.obj")
    c = V - V.mean(axis=0)
    c /= np.abs(c).max()
    features = np.c_[c[:, 0] + 0.5 * c[:, 1] ** 2, c[:, 2]]
    sphere = spherical_conformal_map(V, F, kind="area_balanced", precision="float32")
    assert sphere.success
    return V, F, features, sphere


def angles(A, B):
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(A, B), axis=1), (A * B).sum(axis=1)))


def test_a_subject_registered_from_its_surface_recovers_a_known_rotation(subject, monkeypatch):
    """The target is the subject's own area-balanced sphere turned by a known rotation, with the
    same features at the same vertices: vertex ``i`` belongs at ``R S_i``.  From the surface
    alone (its sphere computed inside) the registration puts it there."""
    V, F, features, sphere = subject
    R = Rotation.from_quat([0.3, -0.5, 0.6, 0.55]).as_matrix()  # scipy normalizes
    target = sphere.U @ R.T
    assert angles(sphere.U, target).mean() > 30.0
    res = register_surface(V, F, features, target, sphere.F, features)
    err = angles(res.U, target)
    assert err.mean() < 0.5 and err.max() < 2.0  # degrees
    assert res.success and not res.warnings and res.folds == 0
    assert np.array_equal(res.F, sphere.F)
    assert res.timings["sphere"] > 0 and res.seconds >= res.timings["sphere"]
    # a given sphere is used as it is: no sphere computed, the same registration

    def no_map(*args, **kwargs):
        raise AssertionError("a sphere was computed although one was given")

    monkeypatch.setattr(atlas_multires, "spherical_conformal_map", no_map)
    given = register_surface(V, F, features, target, sphere.F, features, sphere=sphere.U)
    np.testing.assert_array_equal(given.U, res.U)

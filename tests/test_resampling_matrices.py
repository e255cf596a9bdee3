"""Resampling matrices between spheres: barycentric, ADAP_BARY_AREA (rows sum to 1, the area
integral conserved, averaging when downsampling), labels (majority, nearest), masks, both
directions of a registration, and resample(method=, mask=)."""

import numpy as np
import pytest

from igl_spheremap import (icosphere, registration_matrices, resample, resample_labels,
                           resampling_matrix)
from igl_spheremap.mesh.operators import vertex_areas
from igl_spheremap.uses.resampling import apply


def voronoi_labels(V, k, seed=0):
    seeds = V[np.random.default_rng(seed).choice(V.shape[0], k, replace=False)]
    return np.argmax(V @ seeds.T, axis=1)


@pytest.fixture(scope="module")
def fine_coarse():
    Vf, Ff = icosphere(5, order="freesurfer")
    Vc, Fc = icosphere(3, order="freesurfer")
    return Vf, Ff, Vc, Fc


def test_barycentric_rows_sum_to_one_and_nested_vertices_are_exact(fine_coarse):
    Vf, Ff, Vc, Fc = fine_coarse
    W = resampling_matrix(Vc, Fc, Vf)
    np.testing.assert_allclose(np.asarray(W.sum(axis=1)).ravel(), 1.0)
    np.testing.assert_allclose((W @ Vc)[:Vc.shape[0]], Vc, atol=1e-12)  # nested levels


def test_adap_bary_area_averages_and_conserves_the_area_integral(fine_coarse):
    Vf, Ff, Vc, Fc = fine_coarse
    af, ac = vertex_areas(Vf, Ff), vertex_areas(Vc, Fc)
    af, ac = af / af.sum(), ac / ac.sum()  # the same surface: the same total area
    W = resampling_matrix(Vf, Ff, Vc, Fc, method="adap_bary_area", current_area=af, new_area=ac)
    np.testing.assert_allclose(np.asarray(W.sum(axis=1)).ravel(), 1.0)
    assert W.min() >= 0 and np.diff(W.indptr).mean() > 10  # every fine vertex contributes
    rng = np.random.default_rng(0)
    x = rng.normal(size=Vf.shape[0])
    y, y_bary = W @ x, resampling_matrix(Vf, Ff, Vc) @ x
    assert y.std() < 0.5 * y_bary.std()  # noise is averaged, not sampled
    smooth = Vf[:, 2] + 2.0
    assert ac @ (W @ smooth) == pytest.approx(af @ smooth, rel=1e-3)
    assert abs(ac @ y - af @ x) < 0.05 * np.abs(af * x).sum()
    # upsampling: the forward (barycentric) weights, up to the area correction
    Wu = resampling_matrix(Vc, Fc, Vf, Ff, method="adap_bary_area", current_area=ac, new_area=af)
    assert np.diff(Wu.indptr).max() <= 3
    with pytest.raises(ValueError, match="needs"):
        resampling_matrix(Vf, Ff, Vc, Fc, method="adap_bary_area")
    with pytest.raises(ValueError, match="method"):
        resampling_matrix(Vf, Ff, Vc, method="nearest")


def test_bad_areas_labels_and_spheres_are_refused(fine_coarse):
    """Zero, negative or NaN areas gave rows summing to 0 or NaN, a short area array a numpy
    broadcast error, 3.7 labels came back as 3, and an ellipsoid passed for the sphere was
    resampled by its central projection; each is now a ValueError naming the fault."""
    Vf, Ff, Vc, Fc = fine_coarse
    af, ac = vertex_areas(Vf, Ff), vertex_areas(Vc, Fc)
    for bad, what in ((0.0 * af, f"has {len(af)} values that are not finite, above 0"),
                      (np.r_[np.nan, af[1:]], "has 1 value that is not finite, above 0"),
                      (af[:-1], "one weight per vertex")):
        with pytest.raises(ValueError, match=f"current_area .*{what}"):
            resampling_matrix(Vf, Ff, Vc, Fc, method="adap_bary_area", current_area=bad,
                              new_area=ac)
    W = resampling_matrix(Vc, Fc, Vf)
    with pytest.raises(ValueError, match="labels must be integers"):
        resample_labels(W, np.full(Vc.shape[0], 3.7))
    assert np.array_equal(resample_labels(W, np.full(Vc.shape[0], 3.0)), np.full(Vf.shape[0], 3))
    with pytest.raises(ValueError, match="current_U is not a sphere"):
        resampling_matrix(Vc * [1.0, 2.0, 3.0], Fc, Vf)


def test_labels_round_trip_and_a_mask(fine_coarse):
    Vf, Ff, Vc, Fc = fine_coarse
    labels = voronoi_labels(Vc, 20)
    up = resample_labels(resampling_matrix(Vc, Fc, Vf), labels, "nearest")
    np.testing.assert_array_equal(up[:Vc.shape[0]], labels)
    W = resampling_matrix(Vf, Ff, Vc, Fc, method="adap_bary_area",
                          current_area=vertex_areas(Vf, Ff), new_area=vertex_areas(Vc, Fc))
    assert (resample_labels(W, up, "majority") == labels).mean() > 0.95
    north = (Vc[:, 2] > 0).astype(float)  # a "medial wall": the southern half masked out
    reg = registration_matrices(Vf, Ff, Vc, Fc, target_mask=north)
    out = apply(reg.to_subject, np.ones(Vc.shape[0]))
    assert np.isnan(out[Vf[:, 2] < -0.2]).all()
    np.testing.assert_allclose(out[Vf[:, 2] > 0.2], 1.0)
    assert (resample_labels(reg.to_subject, labels)[Vf[:, 2] < -0.2] == -1).all()
    assert reg.to_target.shape == (Vc.shape[0], Vf.shape[0])


def test_resample_with_adap_bary_area_and_a_mask(fine_coarse):
    Vf, Ff, Vc, Fc = fine_coarse
    x = Vf[:, 0] + 3.0
    res = resample(2.0 * Vf, Ff, Vf, Vc, Fc, data=x, method="adap_bary_area")
    np.testing.assert_allclose(res.V, 2.0 * Vc, atol=1e-12)
    np.testing.assert_allclose(res.data, Vc[:, 0] + 3.0, atol=0.05)
    masked = resample(Vf, Ff, Vf, Vc, Fc, data=x, mask=Vf[:, 2] > 0)
    assert np.isnan(masked.data[Vc[:, 2] < -0.2]).all()

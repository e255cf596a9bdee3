"""icosphere(order="freesurfer"): FreeSurfer's fsaverage order and frame, checked against facts
recorded from FreeSurfer's fsaverage5 lh.sphere (no file needed), and against nilearn's copy
of it when nilearn is installed (the bench extra)."""

import hashlib
from pathlib import Path

import numpy as np
import pytest

from igl_spheremap import count_folds, icosphere

#: SHA-256 of the faces of FreeSurfer's fsaverage5 ``lh.sphere`` as little-endian int32, C
#: order (nilearn 0.14.1's ``datasets/data/fsaverage5/sphere_left.gii.gz``, the same array as
#: FreeSurfer's file).  A fact about the file, recorded so that the test needs neither the
#: file nor the network; the file itself is not vendored (FreeSurfer Software License, and
#: nilearn lists its licence as unknown).
FSAVERAGE5_FACES_SHA256 = "190a5f3f846d2a64095587c7ebc6264432ca2ba904603debeb848c286282a01d"

#: Its first faces and vertices (vertices at radius 100 as stored, to 2 decimals).
FSAVERAGE5_FIRST_FACES = [[0, 2564, 2562], [0, 2562, 2565], [0, 2565, 2567], [0, 2567, 2569],
                          [0, 2569, 2564], [3, 2574, 2572]]
FSAVERAGE5_FIRST_VERTICES = [[0.0, 0.0, 100.0], [27.64, -85.07, 44.72], [89.44, 0.0, 44.72],
                             [27.64, 85.07, 44.72], [-72.36, 52.57, 44.72]]


def test_level5_has_fsaverage5s_faces_index_for_index():
    V, F = icosphere("fsaverage5", order="freesurfer")
    assert V.shape == (10242, 3) and F.shape == (20480, 3) and F.dtype == np.int64
    digest = hashlib.sha256(np.ascontiguousarray(F, dtype="<i4").tobytes()).hexdigest()
    assert digest == FSAVERAGE5_FACES_SHA256
    np.testing.assert_array_equal(F[:6], FSAVERAGE5_FIRST_FACES)
    np.testing.assert_allclose(100.0 * V[:5], FSAVERAGE5_FIRST_VERTICES, atol=0.006)
    assert count_folds(F, V) == 0


def test_levels_are_nested_with_the_geometry_of_libigls_icosphere():
    V4, _ = icosphere(4, order="freesurfer")
    V5, _ = icosphere(5, order="freesurfer")
    np.testing.assert_array_equal(V5[:V4.shape[0]], V4)
    np.testing.assert_allclose(np.linalg.norm(V5, axis=1), 1.0, atol=1e-15)
    Vi = icosphere(5)[0]  # the same point set up to a rotation: same angles from a vertex
    np.testing.assert_allclose(np.sort(V5 @ V5[0]), np.sort(Vi @ Vi[0]), atol=1e-12)


def test_matches_nilearns_fsaverage5_when_installed():
    nilearn = pytest.importorskip("nilearn")
    nib = pytest.importorskip("nibabel")
    path = Path(nilearn.__file__).parent / "datasets" / "data" / "fsaverage5" / "sphere_left.gii.gz"
    if not path.exists():
        pytest.skip("nilearn without fsaverage5")
    Vf, Ff = [a.data for a in nib.load(path).darrays]
    V, F = icosphere(5, order="freesurfer")
    np.testing.assert_array_equal(F, Ff)
    assert np.linalg.norm(100.0 * V - Vf, axis=1).max() < 0.01


def test_bad_levels_and_orders():
    with pytest.raises(ValueError):
        icosphere(10, order="freesurfer")
    with pytest.raises(ValueError):
        icosphere("fsaverage9", order="freesurfer")
    with pytest.raises(TypeError):
        icosphere(2.0, order="freesurfer")
    with pytest.raises(TypeError):
        icosphere("fsaverage5")  # names are FreeSurfer's
    with pytest.raises(ValueError):
        icosphere(2, order="fs_LR")

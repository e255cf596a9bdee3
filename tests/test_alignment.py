"""Geodesic distances (:func:`igl_spheremap.uses.alignment.geodesics`) against exact ones, and
the trimmed Möbius fit of found pairs (:func:`igl_spheremap.uses.alignment.trimmed_fit`)."""

import igl
import numpy as np
from scipy.spatial.transform import Rotation

from conftest import load_mesh
from igl_spheremap.mesh.shapes import icosphere
from igl_spheremap.uses.alignment import (OUTLIER_ANGLE, PAIR_BUDGET, farthest_from, geodesics,
                                         spectral_pairs, trimmed_fit)


def _exact(V, F, source, targets):
    d = igl.exact_geodesic(V, F, np.array([source]), np.zeros(0, np.int64), targets,
                           np.zeros(0, np.int64))
    return (d[0] if isinstance(d, tuple) else d) / np.sqrt(igl.doublearea(V, F).sum() / 2.0)


def test_geodesics_match_exact_geodesics_on_a_mesh_with_needle_triangles():
    """The dinosaur has faces with angles of 178 degrees; the heat method on its own cotangent
    Laplacian is off by up to 1.3 sqrt(area) from vertex 100 (libigl's ``heat_geodesics``,
    the implementation before), on the intrinsic Delaunay triangulation by 0.03."""
    V, F = load_mesh("dino.obj")
    dist = geodesics(V, F)
    targets = np.arange(0, V.shape[0], 7, dtype=np.int64)
    for source in (0, 100, 1785):
        exact = _exact(V, F, source, targets)
        assert np.max(np.abs(dist(source)[targets] - exact)) < 0.06
    several = np.array([100, 1785], dtype=np.int64)
    nearest = np.minimum(_exact(V, F, 100, targets), _exact(V, F, 1785, targets))
    assert np.max(np.abs(dist(several)[targets] - nearest)) < 0.06


def _rotated_pairs():
    V, F = icosphere(3)
    F = np.asarray(F, dtype=np.int64)
    U = V / np.linalg.norm(V, axis=1, keepdims=True)
    R = Rotation.from_rotvec([0.3, -0.5, 0.2]).as_matrix()
    rng = np.random.default_rng(1)
    picks = rng.choice(U.shape[0], 15, replace=False)
    return F, U, R, picks[:3], picks[3:]


def test_trimmed_fit_keeps_every_pair_of_an_exact_rotation():
    F, U, R, lm, pairs = _rotated_pairs()
    fit, keep = trimmed_fit(F, U, lm, U[lm] @ R.T, pairs, U[pairs] @ R.T)
    assert keep.all()
    assert np.max(np.abs(fit.U - U @ R.T)) < 1e-6


def test_trimmed_fit_drops_the_pair_a_mirror_symmetry_turned_over_and_only_it():
    """One pair's partner is its mirror image (x -> -x: a left paw paired with the right one):
    it is dropped, every other pair kept, and the fit is the rotation again."""
    F, U, R, lm, pairs = _rotated_pairs()
    targets = U[pairs] @ R.T
    wrong = int(np.argmax(np.abs(U[pairs, 0])))  # far from the mirror plane
    targets[wrong] = (U[pairs[wrong]] * [-1.0, 1.0, 1.0]) @ R.T
    assert np.arccos(targets[wrong] @ (U[pairs[wrong]] @ R.T)) > OUTLIER_ANGLE
    fit, keep = trimmed_fit(F, U, lm, U[lm] @ R.T, pairs, targets)
    assert np.flatnonzero(~keep).tolist() == [wrong]
    assert np.max(np.abs(fit.U - U @ R.T)) < 1e-6


def test_farthest_points_continued_from_seeds_are_farthest_from_the_seeds_and_each_other():
    """Against a brute-force farthest-point sampling on exact geodesics (fish): the first sample
    is the vertex farthest from the seeds, and each later one maximizes the distance to the
    seeds and the samples before it, to the heat method's accuracy."""
    V, F = load_mesh("fish_lowres.obj")
    dist = geodesics(V, F)
    seeds = np.array([0, 400], dtype=np.int64)
    picks = farthest_from(dist, seeds, 5)
    assert len(set(picks)) == 5 and not set(picks) & set(seeds.tolist())
    every = np.arange(V.shape[0], dtype=np.int64)
    taken = list(seeds)
    for p in picks:
        nearest = np.min([_exact(V, F, int(s), every) for s in taken], axis=0)
        assert nearest[p] > nearest.max() - 0.03
        taken.append(p)


def test_the_functional_map_adds_pairs_only_up_to_the_budget_of_landmarks():
    """With ``k`` given landmarks, ``spectral_pairs`` samples at most ``PAIR_BUDGET - k``
    vertices (fish onto itself): some with 20 landmarks, none with 32."""
    V, F = load_mesh("fish_lowres.obj")
    F = np.asarray(F, dtype=np.int64)
    dist = geodesics(V, F)
    for k in (20, PAIR_BUDGET):
        lm = np.array([0] + farthest_from(dist, np.array([0]), k - 1), dtype=np.int64)
        p1, p2 = spectral_pairs(V, F, V, F, lm, lm).samples
        assert p1.size <= max(0, PAIR_BUDGET - k) and (p1.size > 0) == (k < PAIR_BUDGET)
        assert not np.isin(p1, lm).any()

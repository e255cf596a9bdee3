"""Invariance and determinism of spherical_conformal_map (property tests).

A conformal map of a surface onto the sphere is unique up to a Möbius
transformation; with Möbius normalization (centroid at the origin) it is unique
up to a rotation.  So rigid motions and uniform scalings of the input, and a
relabeling of its vertices, must give the same map up to a rotation of the
sphere (and the permutation).
"""

import functools
import pathlib

import igl
import numpy as np
from hypothesis import given, settings, strategies as st
from scipy.spatial.transform import Rotation

import igl_spheremap

DATA = pathlib.Path(__file__).parent / "data"
V0, F0 = igl.read_triangle_mesh(str(DATA / "fish_lowres.obj"))


@functools.cache
def reference():
    """The fish's map, computed once, on first use (not at collection)."""
    return igl_spheremap.spherical_conformal_map(V0, F0).U


def _rotation_residual(A, B):
    """max_i |A_i Q - B_i| for the best rotation Q (orthogonal Procrustes), and det Q."""
    W, _, Zt = np.linalg.svd(A.T @ B)
    Q = W @ Zt
    return float(np.max(np.linalg.norm(A @ Q - B, axis=1))), float(np.linalg.det(Q))


@settings(max_examples=6, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), log_scale=st.floats(-6.0, 6.0))
def test_rigid_motion_and_scaling_give_a_rotated_map(seed, log_scale):
    rng = np.random.default_rng(seed)
    R = Rotation.random(random_state=rng).as_matrix()
    t = rng.normal(size=3) * 10.0 ** log_scale
    V = (10.0 ** log_scale) * V0 @ R.T + t
    result = igl_spheremap.spherical_conformal_map(V, F0)
    assert result.success
    residual, det = _rotation_residual(reference(), result.U)
    assert det > 0
    assert residual < 1e-6


@settings(max_examples=4, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_vertex_relabeling_gives_the_permuted_map(seed):
    rng = np.random.default_rng(seed)
    perm = rng.permutation(V0.shape[0])        # new vertex k is old vertex perm[k]
    inverse = np.argsort(perm)
    V = V0[perm]
    F = inverse[F0][rng.permutation(F0.shape[0])]
    result = igl_spheremap.spherical_conformal_map(V, F)
    assert result.success
    residual, det = _rotation_residual(reference()[perm], result.U)
    assert det > 0
    assert residual < 1e-6


def test_same_input_gives_bit_identical_output():
    a = igl_spheremap.spherical_conformal_map(V0, F0).U
    b = igl_spheremap.spherical_conformal_map(V0.copy(), F0.copy()).U
    assert np.array_equal(a, b)


def test_bundled_dino_is_bit_identical_across_runs():
    # dino exercises the star map, the fold barrier and its refactorizations.
    from importlib import resources
    path = resources.files("igl_spheremap") / "data" / "dino.obj"
    V, F = igl.read_triangle_mesh(str(path))
    a = igl_spheremap.spherical_conformal_map(V, F)
    b = igl_spheremap.spherical_conformal_map(V, F)
    assert a.success and len(a.rounds) >= 2
    assert np.array_equal(a.U, b.U)

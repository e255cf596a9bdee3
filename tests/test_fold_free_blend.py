"""fold_free_blend: a proposed map pulled back toward a fold-free one until no face folds.

Folds are counted by an independent reference, the sign of ``det [u_i, u_j, u_k]`` of each
image face (numpy's determinant).
"""

import numpy as np

from conftest import make_icosphere
from igl_spheremap.sphere.folds import fold_free_blend


def _folded(F, U):
    return np.linalg.det(U[F]) <= 0.0


def _proposal(V, seed, size):
    rng = np.random.default_rng(seed)
    X = V + size * rng.standard_normal(V.shape)
    return X / np.linalg.norm(X, axis=1, keepdims=True)


def test_blend_is_fold_free_and_moves_each_vertex_along_its_own_step():
    V, F = make_icosphere(3)
    U_new = _proposal(V, 0, 0.05)
    assert _folded(F, U_new).sum() > 20  # the proposal folds
    U, alpha = fold_free_blend(F, V, U_new)
    assert not _folded(F, U).any()
    assert np.all((alpha >= 0.0) & (alpha <= 1.0))
    assert 0 < np.count_nonzero(alpha < 1.0) < V.shape[0]  # only some steps cut back
    np.testing.assert_array_equal(U[alpha == 0.0], V[alpha == 0.0])  # back to the bit
    np.testing.assert_array_equal(U[alpha == 1.0], U_new[alpha == 1.0])
    np.testing.assert_allclose(np.linalg.norm(U, axis=1), 1.0, atol=1e-15)
    # a cut-back vertex lies on the great-circle arc from its old to its new position
    cut = (alpha > 0.0) & (alpha < 1.0)
    normal = np.cross(V[cut], U_new[cut])
    np.testing.assert_allclose(np.einsum("ij,ij->i", normal, U[cut]), 0.0, atol=1e-12)


def test_it_cuts_back_the_corners_of_folded_faces_and_leaves_most_steps_whole():
    V, F = make_icosphere(3)
    U_new = _proposal(V, 1, 0.05)
    _, alpha = fold_free_blend(F, V, U_new)
    corners = np.unique(F[_folded(F, U_new)])
    assert np.all(alpha[corners] < 1.0)
    assert np.count_nonzero(alpha == 1.0) > V.shape[0] // 2


def test_fixed_vertices_keep_their_full_step():
    V, F = make_icosphere(3)
    U_new = _proposal(V, 2, 0.05)
    fixed = np.zeros(V.shape[0], dtype=bool)
    fixed[::7] = True
    U, alpha = fold_free_blend(F, V, U_new, fixed=fixed)
    np.testing.assert_array_equal(U[fixed], U_new[fixed])
    assert np.all(alpha[fixed] == 1.0)
    # a face left folded has a fixed corner, and its other corners are back at the old map
    bad = F[_folded(F, U)]
    assert np.all(fixed[bad].any(axis=1))
    assert np.all(alpha[bad[~fixed[bad]]] == 0.0)


def test_a_fold_free_proposal_is_returned_as_it_is():
    V, F = make_icosphere(2)
    U_new = _proposal(V, 3, 1e-3)
    assert not _folded(F, U_new).any()
    U, alpha = fold_free_blend(F, V, U_new)
    np.testing.assert_array_equal(U, U_new)
    assert np.all(alpha == 1.0)

"""fold_free_blend: a proposed map pulled back toward a fold-free one until no face folds.

Folds are counted by an independent reference, the sign of ``det [u_i, u_j, u_k]`` of each
image face (numpy's determinant).
"""

import numpy as np
import pytest

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


def test_it_cuts_back_the_corners_that_close_a_folded_face_and_keeps_the_rest():
    V, F = make_icosphere(3)
    U_new = _proposal(V, 1, 0.05)
    U, alpha = fold_free_blend(F, V, U_new)
    assert not _folded(F, U).any()
    folded = F[_folded(F, U_new)]
    assert np.all((alpha[folded] < 1.0).any(axis=1))  # each folded face is cut back
    assert np.count_nonzero(alpha == 1.0) > V.shape[0] // 2
    # Corners whose step closes none of the folded faces they are in keep it whole here:
    # a face's determinant with the corner's row replaced by its step is the derivative
    # in the corner's share of the step (the determinant is linear in each row).
    step = U_new - V
    opening = [v for v in np.unique(folded)
               if not any(v in face and _closes(face, v, U_new, step) for face in folded)]
    assert opening
    assert np.all(alpha[opening] == 1.0)


def _closes(face, v, U, step):
    rows = U[face].copy()
    rows[list(face).index(v)] = step[v]
    return np.linalg.det(rows) < 0.0


def test_with_all_corners_every_corner_of_a_folded_face_is_cut_back():
    V, F = make_icosphere(3)
    U_new = _proposal(V, 1, 0.05)
    U, alpha = fold_free_blend(F, V, U_new, corners="all")
    assert not _folded(F, U).any()
    corners = np.unique(F[_folded(F, U_new)])
    assert np.all(alpha[corners] < 1.0)
    # the closing corners alone keep more of the step
    assert alpha.sum() < fold_free_blend(F, V, U_new)[1].sum()


def test_an_unknown_choice_of_corners_is_refused():
    V, F = make_icosphere(1)
    with pytest.raises(ValueError, match="corners must be 'closing' or 'all'"):
        fold_free_blend(F, V, V, corners="some")


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

"""igl_spheremap.untangle.untangle_folds: local Tutte re-embedding of folded patches."""

import igl
import numpy as np

from igl_spheremap import count_folds, folded_faces
from igl_spheremap.untangle import untangle_folds


def _rings(F, n, seeds, k):
    """Vertices within k edge rings of the seeds (igl.adjacency_matrix)."""
    A = igl.adjacency_matrix(F).tocsr()
    inside = np.zeros(n, dtype=bool)
    inside[seeds] = True
    for _ in range(k):
        inside |= (A @ inside.astype(np.float64)) > 0
    return inside


def _drag_past_neighbor(F, U, v, factor=2.5):
    """Move vertex v along the chord to one of its neighbors, past it: local folds."""
    A = igl.adjacency_matrix(F).tocsr()
    w = A[v].indices[0]
    U = U.copy()
    U[v] = U[v] + factor * (U[w] - U[v])
    U[v] /= np.linalg.norm(U[v])
    return U


def test_one_folded_patch_is_untangled_locally(icosphere):
    V, F = icosphere(3)
    U = _drag_past_neighbor(F, V, 100)
    before = U.copy()
    assert count_folds(F, U) > 0
    out, remaining = untangle_folds(F, U)
    assert np.array_equal(U, before)  # the input is not modified
    assert remaining == 0 == count_folds(F, out)
    assert np.abs(np.linalg.norm(out, axis=1) - 1.0).max() < 1e-14
    changed = np.any(out != U, axis=1)
    assert changed[100]
    # Outside the patch (a few rings around the folded faces) nothing moves.
    patch = _rings(F, V.shape[0], F[folded_faces(F, U)].ravel(), 3)
    assert not changed[~patch].any()
    assert np.array_equal(out[~patch], U[~patch])


def test_two_separate_patches(icosphere):
    V, F = icosphere(3)
    far = int(np.argmin(V @ V[100]))  # the antipode of vertex 100
    U = _drag_past_neighbor(F, _drag_past_neighbor(F, V, 100), far, 1.8)
    seeds = F[folded_faces(F, U)].ravel()
    assert {100, far} <= set(seeds.tolist())
    out, remaining = untangle_folds(F, U)
    assert remaining == 0 == count_folds(F, out)
    changed = np.any(out != U, axis=1)
    assert not changed[~_rings(F, V.shape[0], seeds, 3)].any()


def test_real_map_with_a_local_fold(conformal_map):
    V, F, result, _ = conformal_map("goathead.obj")
    assert result.folds == 0
    U = _drag_past_neighbor(F, result.U, 1000, 3.0)
    assert count_folds(F, U) > 0
    out, remaining = untangle_folds(F, U)
    assert remaining == 0 == count_folds(F, out)
    changed = np.any(out != U, axis=1)
    assert changed.sum() < 100
    assert not changed[~_rings(F, V.shape[0], F[folded_faces(F, U)].ravel(), 12)].any()


def test_fold_free_input_is_returned_as_a_copy(icosphere):
    V, F = icosphere(2)
    out, remaining = untangle_folds(F, V)
    assert remaining == 0 and out is not V and np.array_equal(out, V)


def test_remaining_folds_are_reported_honestly(icosphere):
    """A vertex flung across the sphere is not a local fold: whatever is left is counted."""
    V, F = icosphere(3)
    U = V.copy()
    U[100] = -U[100]
    out, remaining = untangle_folds(F, U, max_rings=3)
    assert remaining == count_folds(F, out)
    assert remaining <= count_folds(F, U)

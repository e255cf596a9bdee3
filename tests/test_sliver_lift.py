"""lift_slivers: faces of a fold-free map below their float32 rounding margin moved clear of it.

Signed volumes come from an independent reference, numpy's ``det [u_i, u_j, u_k]``, and the
margin from the bound it documents, ``SAFETY (u P + 3 u^2 + u^3)`` with ``P`` the chord
perimeter and ``u = 2**-24``; a stored map is checked by rounding ``100 U`` to float32.
"""

import numpy as np
import pytest

from conftest import make_icosphere
from igl_spheremap.sphere.folds import SAFETY
from igl_spheremap.sphere.sliver_lift import lift_slivers

U32 = 2.0 ** -24


def _dets(F, U):
    return np.linalg.det(U[F])


def _margins(F, U):
    X = U[F]
    P = sum(np.linalg.norm(X[:, a] - X[:, (a + 1) % 3], axis=1) for a in range(3))
    return SAFETY * (U32 * P + 3 * U32 ** 2 + U32 ** 3)


def _slivered(level, faces, depth):
    """An icosphere whose faces ``faces`` have a corner pushed to ``depth`` of the way from
    the opposite edge's midpoint: slivers below the float32 margin, nothing folded."""
    V, F = make_icosphere(level)
    U = V.copy()
    for f in faces:
        a, b, c = F[f]
        mid = 0.5 * (U[b] + U[c])
        p = mid + depth * (U[a] - mid)
        U[a] = p / np.linalg.norm(p)
    return V, F, U


def test_slivers_clear_their_margin_and_nothing_else_moves_or_folds():
    V, F, U = _slivered(3, [0, 200, 700], 1e-9)
    below = _dets(F, U) <= _margins(F, U)
    assert below.sum() >= 3 and np.all(_dets(F, U) > 0)  # slivers, not folds
    out = lift_slivers(F, U, "float32")
    d = _dets(F, out)
    assert np.all(d > _margins(F, out))
    moved = np.flatnonzero(np.any(out != U, axis=1))
    assert 1 <= moved.size <= 3 * below.sum()
    assert np.isin(moved, F[below]).all()  # only corners of the slivers move
    np.testing.assert_allclose(np.linalg.norm(out[moved], axis=1), 1.0, atol=1e-15)
    # stored as float32 at radius 100 and read back, no face folds
    stored = (100.0 * out).astype(np.float32).astype(np.float64)
    assert np.all(_dets(F, stored) > 0)


def test_float64_has_no_margin_and_returns_the_map_unchanged():
    V, F, U = _slivered(2, [0], 1e-9)
    out = lift_slivers(F, U, "float64")
    np.testing.assert_array_equal(out, U)
    assert out is not U


def test_unknown_precision_is_refused():
    V, F = make_icosphere(1)
    with pytest.raises(ValueError, match="precision"):
        lift_slivers(F, V, "float16")


def test_a_crowded_cluster_below_the_margin_is_left_and_isolated_slivers_are_lifted():
    """A cap of the map crowded towards its centre (offsets scaled by ``exp(-20 (R - d) / R)``
    at distance ``d < R``, as a punctured Tutte map crowds far from its puncture): more than
    ``LIFT_CLUSTER`` faces there below the margin, none folded.  A single-corner move could
    lift a few of them, not the cluster; it is left as it is for the re-embeddings, and a
    sliver elsewhere on the same map is lifted."""
    from igl_spheremap.sphere.sliver_lift import LIFT_CLUSTER

    V, F, U = _slivered(3, [700], 1e-9)
    centre, R = U[F[0, 0]], 0.8
    d = np.arccos(np.clip(U @ centre, -1.0, 1.0))
    near = np.flatnonzero(d < R)
    crowded = centre + np.exp(-20.0 * (R - d[near]) / R)[:, None] * (U[near] - centre)
    U[near] = crowded / np.linalg.norm(crowded, axis=1, keepdims=True)
    below = _dets(F, U) <= _margins(F, U)
    cluster = below & np.any(np.isin(F, near), axis=1)
    assert np.all(_dets(F, U) > 0) and cluster.sum() > LIFT_CLUSTER and below[700]
    out = lift_slivers(F, U, "float32")
    np.testing.assert_array_equal(out[near], U[near])
    assert _dets(F, out)[700] > _margins(F, out)[700]

"""igl_spheremap.folding.local_repair.local_repair: untangle, then Algorithm 1 over the repaired region."""

import igl
import numpy as np
import pytest

from igl_spheremap import MapOptions, count_folds
from igl_spheremap.folding.local_repair import local_repair

from conftest import drag_past_neighbor


def _operators(V, F):
    """libigl's cotangent Laplacian and barycentric vertex areas scaled to 4 pi."""
    L = igl.cotmatrix(V, F)
    area = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_BARYCENTRIC).diagonal()
    return L, area * (4.0 * np.pi / area.sum())


def test_dragged_vertex_is_repaired_back_to_the_identity(icosphere):
    # The identity of an icosphere is (nearly) a critical point of the
    # harmonic energy; with every vertex outside the region fixed, local
    # re-minimization from the untangled map must come back to it.
    V, F = icosphere(4)
    L, area = _operators(V, F)
    U = drag_past_neighbor(F, V, 100, 2.5)
    assert count_folds(F, U) > 0
    U_init, res, region, patched = local_repair(L, area, F, U, MapOptions(gtol=1e-9, metric="H1"))
    assert count_folds(F, U_init) == 0 == count_folds(F, res.U)
    assert not patched  # a Tutte patch or a kernel move untangles one dragged vertex
    assert res.converged and res.frozen == 0
    assert region[100] and region.sum() <= 0.1 * V.shape[0]
    assert np.array_equal(res.U[~region], U[~region])
    assert np.abs(np.linalg.norm(res.U, axis=1) - 1.0).max() < 1e-14
    # V agrees with U outside the region, so it competes: the repaired map
    # is at least as good, and (V being nearly critical) close to it.
    def energy(X):
        return -0.5 * np.sum(X * (L @ X))

    assert energy(res.U) <= energy(V) + 1e-12
    # The reported energies are of the whole map.
    assert res.energy_history[0] == pytest.approx(energy(U_init), rel=1e-12)
    assert res.energy == pytest.approx(energy(res.U), rel=1e-12)
    assert np.abs(res.U - V).max() < 1e-3
    # Independent check of the stopping rule: tangential part of -M^{-1} L U
    # over the region.
    H = -(L @ res.U) / area[:, None]
    G = H - np.sum(H * res.U, axis=1)[:, None] * res.U
    assert np.sqrt(area[region] @ np.sum(G[region] ** 2, axis=1) / area[region].sum()) < 1e-9


def test_folds_that_are_not_isolated_are_left_to_the_star_map(icosphere):
    V, F = icosphere(3)
    L, area = _operators(V, F)
    U = drag_past_neighbor(F, V, 100, 2.5)
    assert local_repair(L, area, F, U, MapOptions(), max_fraction=0.0) is None
    # Map every vertex to its antipode: all faces fold.
    assert local_repair(L, area, F, -V, MapOptions()) is None


def test_a_fold_free_map_needs_no_repair(icosphere):
    V, F = icosphere(2)
    L, area = _operators(V, F)
    assert local_repair(L, area, F, V, MapOptions()) is None

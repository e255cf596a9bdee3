"""igl_spheremap.optimize.direction: L2 and H1 directions on the free vertices, with the gauge."""

import igl
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from igl_spheremap.optimize.gauge import MobiusGauge
from igl_spheremap.optimize.direction import H1Metric, L2Metric, SearchDirection


def _problem(mesh):
    V, F = mesh("fish_lowres.obj")
    L = igl.cotmatrix(V, F).tocsr()
    a = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_BARYCENTRIC).diagonal()
    a = a * (4 * np.pi / a.sum())
    N = igl.per_vertex_normals(V, F)
    return L, a, N / np.linalg.norm(N, axis=1, keepdims=True)


def _tangent(U, X):
    return X - np.einsum("ij,ij->i", U, X)[:, None] * U


def test_l2_direction_is_the_riemannian_gradient(mesh):
    L, a, U = _problem(mesh)
    H = -(L @ U) / a[:, None]
    free = np.ones(len(a), bool)
    G, X, MG = SearchDirection(a, L2Metric(), None, free)(U, H)
    assert np.abs(G - _tangent(U, H)).max() < 1e-12 * np.abs(H).max()
    assert X is G and np.array_equal(MG, G * a[:, None])


def test_h1_direction_is_the_projected_sobolev_gradient(mesh):
    """X = P(K^{-1} M G), K = M - L (spsolve reference), zero on frozen vertices, and a
    descent direction: <G, X>_M > 0."""
    L, a, U = _problem(mesh)
    H = -(L @ U) / a[:, None]
    free = np.ones(len(a), bool)
    free[::7] = False
    G, X, MG = SearchDirection(a, H1Metric(L, a, "superlu"), None, free)(U, H)
    G_ref = _tangent(U, H)
    G_ref[~free] = 0
    assert np.abs(G - G_ref).max() < 1e-12 * np.abs(H).max()
    K = (sp.diags(a) - L).tocsc()[free][:, free]
    Y = np.zeros_like(U)
    Y[free] = spla.spsolve(K, (G_ref * a[:, None])[free])
    X_ref = _tangent(U, Y)
    X_ref[~free] = 0
    assert np.abs(X - X_ref).max() < 1e-9 * np.abs(X_ref).max()
    assert np.sum(MG * X) > 0


def test_gauge_keeps_the_centroid_still_to_first_order(mesh):
    L, a, U = _problem(mesh)
    H = -(L @ U) / a[:, None]
    free = np.ones(len(a), bool)
    for metric in (L2Metric(), H1Metric(L, a, "superlu")):
        G, X, _ = SearchDirection(a, metric, MobiusGauge(a), free)(U, H)
        assert np.linalg.norm(a @ G) < 1e-12 * np.abs(a[:, None] * H).sum()
        assert np.linalg.norm(a @ X) < 1e-12 * np.abs(a[:, None] * X).sum()


def test_h1_set_up_is_due_when_the_free_set_settled(mesh):
    L, a, _ = _problem(mesh)
    metric = H1Metric(L, a, "superlu")
    free = np.ones(len(a), bool)
    metric.setup(free, k=0)

    class _Free:
        last_freeze = 0
        free = np.ones(len(a), bool)

    c = _Free()
    assert not metric.due(30, c, 25)               # same free set
    c.free = c.free.copy()
    c.free[3] = False
    c.last_freeze = 29
    assert not metric.due(30, c, 25)               # froze one iteration ago
    assert metric.due(31, c, 25)
    assert not metric.due(20, c, 25) if c.last_freeze < 20 else True

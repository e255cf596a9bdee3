"""The functional map start (#19 item 3): an exact isometry is recovered vertex for vertex, and
landmark pairs choose among the isometries of a symmetric surface."""

from pathlib import Path

import igl
import numpy as np
import pytest

import igl_spheremap.uses.functional_map as fm
from igl_spheremap.mesh.shapes import icosphere
from igl_spheremap.uses.functional_map import laplace_basis, spectral_correspondence


def fish():
    V, F = igl.read_triangle_mesh(str(Path(__file__).parent / "data" / "fish_lowres.obj"))
    return V, np.asarray(F, np.int64)


def test_the_basis_is_orthonormal_in_the_mass_matrix_and_starts_with_the_constant():
    V, F = fish()
    b = laplace_basis(V * 3.0, F, 20)
    G = b.evecs.T @ (b.mass[:, None] * b.evecs)
    np.testing.assert_allclose(G, np.eye(20), atol=1e-8)
    assert abs(b.evals[0]) < 1e-8 and np.all(np.diff(b.evals) >= -1e-9)
    np.testing.assert_allclose(b.mass.sum(), 1.0, rtol=1e-12)  # scaled to area 1
    np.testing.assert_allclose(np.abs(b.evecs[:, 0]), 1.0, rtol=1e-6)


def renumbered_copy(V, F):
    """Surface 1 rotated, scaled by 2 and renumbered: ``(V2, F2, inv)``, vertex ``i`` of
    surface 1 being vertex ``inv[i]`` of surface 2."""
    rng = np.random.default_rng(3)
    perm = rng.permutation(V.shape[0])  # vertex i of surface 1 is vertex inv[i] of surface 2
    inv = np.argsort(perm)
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    Q *= np.sign(np.linalg.det(Q))
    return 2.0 * V[perm] @ Q.T, inv[F], inv


def test_a_rotated_and_renumbered_copy_is_recovered():
    """Surface 2 = surface 1 rotated, scaled and with its vertices renumbered: an isometry up to
    scale, so the vertex map should send (nearly) every vertex to its copy."""
    V, F = fish()
    V2, F2, inv = renumbered_copy(V, F)
    T = spectral_correspondence(V, F, V2, F2)
    miss = np.linalg.norm(V2[T] - V2[inv], axis=1) / np.linalg.norm(np.ptp(V2, axis=0))
    assert np.mean(T == inv) > 0.9
    assert miss.mean() < 0.01


def test_zoomout_on_samples_recovers_the_copy_and_answers_only_where_asked(monkeypatch):
    """ZoomOut's iterations on 300 uniform samples of each surface (as on a large surface): the
    functional map they induce still sends the vertices asked for to their copies, and the
    samples are all the vertices when there are few enough."""
    V, F = fish()
    V2, F2, inv = renumbered_copy(V, F)
    assert np.array_equal(fm.samples(V.shape[0]), np.arange(V.shape[0]))
    S = fm.samples(V.shape[0], 300)
    assert S.size == 300 and np.all(np.diff(S) > 0)
    monkeypatch.setattr(fm, "ZOOM_SAMPLES", 300)
    at = np.arange(0, V.shape[0], 7)
    T = spectral_correspondence(V, F, V2, F2, at=at)
    assert T.shape == at.shape
    miss = np.linalg.norm(V2[T] - V2[inv[at]], axis=1) / np.linalg.norm(np.ptp(V2, axis=0))
    assert np.mean(T == inv[at]) > 0.8
    assert miss.mean() < 0.02


@pytest.mark.parametrize("turn", [False, True])
def test_landmarks_choose_between_the_isometries_of_a_symmetric_surface(turn):
    """A triaxial ellipsoid (icosphere, level 2, axes 1 : 1.6 : 2.3) is mapped onto itself by the
    identity and by the half turn about its y axis, which the wave kernel signatures cannot tell
    apart.  Four landmark pairs of either isometry make the vertex map that isometry, vertex for
    vertex; one vertex map cannot be both, so the landmarks must be what decides."""
    V, F = icosphere(2)
    V = V * np.array([1.0, 1.6, 2.3])
    turned = V * np.array([-1.0, 1.0, -1.0])  # the icosphere's vertex set is symmetric this way
    half_turn = np.array([np.argmin(np.sum((V - p) ** 2, axis=1)) for p in turned])
    assert np.abs(V[half_turn] - turned).max() < 1e-12
    truth = half_turn if turn else np.arange(V.shape[0])
    lm = np.random.default_rng(0).choice(V.shape[0], 4, replace=False)
    T = spectral_correspondence(V, F, V, F, landmarks=(lm, truth[lm]))
    assert np.mean(T == truth) > 0.95


def test_a_map_contradicts_landmarks_that_more_than_a_fifth_of_land_elsewhere():
    """With ``C`` the identity each vertex of a surface mapped onto itself is its own partner:
    landmark pairs ``(l, l)`` are met, and pairs ``(l, half turn of l)`` on the ellipsoid above
    are not, except at the turn's two fixed points."""
    V, F = icosphere(2)
    V = V * np.array([1.0, 1.6, 2.3])
    b = laplace_basis(V, F, 40)
    turned = V * np.array([-1.0, 1.0, -1.0])
    half_turn = np.array([np.argmin(np.sum((V - p) ** 2, axis=1)) for p in turned])
    lm = np.flatnonzero(half_turn != np.arange(V.shape[0]))[::10]
    assert not fm.contradicts(b, b, np.eye(30), (lm, lm))
    assert fm.contradicts(b, b, np.eye(30), (lm, half_turn[lm]))


def test_wave_kernel_maps_are_the_wave_kernel_between_the_vertex_and_every_vertex():
    """Column ``(l, e)`` is ``sum_i f_e(lambda_i) phi_i(at_l) phi_i`` (unit mass norm): the kernel
    is symmetric, so the value at vertex ``b`` of ``a``'s map times ``a``'s norm equals the value
    at ``a`` of ``b``'s map times ``b``'s; and the diagonal is the wave kernel signature of the
    same energies (before scaling)."""
    V, F = fish()
    b = laplace_basis(V, F, 60)
    a, c = 5, 400
    raw = fm.wave_kernel_maps(b, [a, c], energies=6, eigenpairs=60)
    phi, lam = b.evecs[:, 1:60], np.log(b.evals[1:60])
    sigma = fm.WKS_WIDTH * (lam[-1] - lam[0]) / 6
    e = np.linspace(lam[0] + 2 * sigma, lam[-1] - 2 * sigma, 6)
    filt = np.exp(-(e[None, :] - lam[:, None]) ** 2 / (2 * sigma ** 2))
    filt /= filt.sum(axis=0)
    K_ac = (phi[a] * phi[c]) @ filt  # the wave kernel between a and c at each energy
    norm_a = np.sqrt(b.mass @ ((phi * phi[a]) @ filt) ** 2)
    norm_c = np.sqrt(b.mass @ ((phi * phi[c]) @ filt) ** 2)
    np.testing.assert_allclose(raw[c, :6] * norm_a, K_ac, rtol=1e-10)
    np.testing.assert_allclose(raw[a, 6:] * norm_c, K_ac, rtol=1e-10)
    np.testing.assert_allclose(raw[a, :6] * norm_a, (phi[a] ** 2) @ filt, rtol=1e-10)


@pytest.mark.parametrize("chunk", [7, 2048])
def test_nearest_rows_are_the_exact_nearest_neighbours(chunk):
    # 30 dimensions as in ZoomOut's first iteration; 1,000 rows of X (not a multiple of the
    # chunk) against 800 of Y.  Each row of X is one of Y's first 700 rows plus noise far
    # below the gap between Y's rows, so the nearest row is unique in single precision, and
    # scipy's k-d tree (float64) is the reference.  Y's last 100 rows are three times rows
    # it has: they have the larger inner product with X's rows near those, not the nearer.
    from scipy.spatial import cKDTree
    rng = np.random.default_rng(5)
    Y = rng.normal(size=(700, 30))
    Y = np.vstack([Y, 3.0 * Y[:100]])
    truth = rng.integers(0, 700, size=1000)
    X = Y[truth] + 1e-3 * rng.normal(size=(1000, 30))
    got = fm.nearest_rows(X, Y, chunk=chunk)
    assert got.dtype == np.int64 and got.shape == (1000,)
    np.testing.assert_array_equal(got, cKDTree(Y).query(X)[1])
    np.testing.assert_array_equal(got, truth)

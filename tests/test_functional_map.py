"""The functional map start (#19 item 3): an exact isometry is recovered vertex for vertex."""

from pathlib import Path

import igl
import numpy as np

import igl_spheremap.uses.functional_map as fm
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

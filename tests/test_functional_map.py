"""The functional map start (#19 item 3): an exact isometry is recovered vertex for vertex."""

from pathlib import Path

import igl
import numpy as np

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


def test_a_rotated_and_renumbered_copy_is_recovered():
    """Surface 2 = surface 1 rotated, scaled and with its vertices renumbered: an isometry up to
    scale, so the vertex map should send (nearly) every vertex to its copy."""
    V, F = fish()
    rng = np.random.default_rng(3)
    perm = rng.permutation(V.shape[0])  # vertex i of surface 1 is vertex inv[i] of surface 2
    inv = np.argsort(perm)
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    Q *= np.sign(np.linalg.det(Q))
    V2 = 2.0 * V[perm] @ Q.T
    F2 = inv[F]
    T = spectral_correspondence(V, F, V2, F2)
    miss = np.linalg.norm(V2[T] - V2[inv], axis=1) / np.linalg.norm(np.ptp(V2, axis=0))
    assert np.mean(T == inv) > 0.9
    assert miss.mean() < 0.01

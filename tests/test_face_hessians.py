"""The per-face Hessians of the conformal-distortion energy (the Newton metric's blocks) and
their positive part; the closed-form projection of planar energies of ``|J|^2`` and ``det J``."""

import os

import numpy as np
import pytest

from igl_spheremap.mesh.frames import tangent_bases
from igl_spheremap.mesh.operators import to_sphere_area, vertex_areas
from igl_spheremap.optimize.conformal_distortion import ConformalDistortionEnergy
import igl_spheremap.optimize.face_hessians as face_hessians
from igl_spheremap.optimize.face_hessians import (invariant_hessians, positive_part,
                                                 projected_tangent_hessians, tangent_hessians)


@pytest.fixture(scope="module")
def mapped(stretched):
    """``(F, U, energy)`` of the shared ``stretched`` map (conftest)."""
    V, F, U = stretched
    return F, U, ConformalDistortionEnergy(V, F, to_sphere_area(vertex_areas(V, F)))


def _face_energies(E, U):
    c, _, _, s = E.terms(U)
    return c / s


def _blocks(E, U, frames):
    c, s, (Q, e) = E.evaluate(U).cache
    return tangent_hessians(E.F, E.lam, U, c, s, Q, e, frames)


def test_face_hessians_match_second_differences_of_each_face_term(mapped):
    """``z_f^T H_f z_f`` is the second derivative of ``c_f / s_f`` along the displacement with
    tangent coordinates ``z`` (central second differences, extrapolated, per face)."""
    F, U, E = mapped
    B = tangent_bases(U)
    H = _blocks(E, U, (B[:, :, 0], B[:, :, 1]))
    z = np.random.default_rng(1).standard_normal((U.shape[0], 2))
    D = z[:, :1] * B[:, :, 0] + z[:, 1:] * B[:, :, 1]
    zf = z[F].reshape(-1, 6)
    quadratic = np.einsum("fi,fij,fj->f", zf, H, zf)

    def difference(h):
        return (_face_energies(E, U + h * D) - 2.0 * _face_energies(E, U)
                + _face_energies(E, U - h * D)) / h ** 2

    h = 1e-4  # Richardson extrapolation removes the O(h^2) term of the central difference
    second = (4.0 * difference(h / 2) - difference(h)) / 3.0
    scale = np.abs(H).max(axis=(1, 2)) * (zf * zf).sum(axis=1)
    assert np.abs(quadratic - second).max() < 1e-5 * scale.max()
    assert np.all(np.abs(quadratic - second) <= 1e-4 * scale)


def test_positive_part_clips_negative_eigenvalues_only():
    """Same eigenvectors, eigenvalues ``max(w, 0)``; a positive semidefinite matrix is kept."""
    rng = np.random.default_rng(2)
    A = rng.standard_normal((50, 6, 6))
    H = A + A.transpose(0, 2, 1)
    P = positive_part(H)
    w, Vec = np.linalg.eigh(H)
    expected = np.einsum("fij,fj,fkj->fik", Vec, np.maximum(w, 0.0), Vec)
    assert np.allclose(P, expected, atol=1e-12 * np.abs(H).max())
    assert np.linalg.eigvalsh(P).min() > -1e-12 * np.abs(H).max()
    psd = np.matmul(A, A.transpose(0, 2, 1))
    assert np.allclose(positive_part(psd), psd, rtol=0, atol=1e-12 * np.abs(psd).max())


@pytest.mark.parametrize("threads", [1, 2, 3])
def test_projected_blocks_in_threads_are_the_serial_ones_to_the_bit(mapped, monkeypatch, threads):
    """Chunking the faces over threads changes no block: each is its own face's alone."""
    F, U, E = mapped
    monkeypatch.setattr(face_hessians, "THREAD_CHUNK", 7)  # several chunks on a small mesh
    B = tangent_bases(U)
    frames = (B[:, :, 0], B[:, :, 1])
    c, s, (Q, e) = E.evaluate(U).cache
    serial = positive_part(tangent_hessians(E.F, E.lam, U, c, s, Q, e, frames))
    chunked = projected_tangent_hessians(E.F, E.lam, U, c, s, Q, e, frames, threads=threads)
    assert np.array_equal(chunked, serial)


def test_default_threads_follow_omp_num_threads(monkeypatch):
    """``OMP_NUM_THREADS`` (Dask sets 1 in its workers) bounds the threads; unset or not a
    positive integer, the process's CPUs do."""
    monkeypatch.setenv("OMP_NUM_THREADS", "1")
    assert face_hessians.default_threads() == 1
    monkeypatch.setenv("OMP_NUM_THREADS", "3")
    assert face_hessians.default_threads() == 3
    cpus = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    for value in ("0", "two", ""):
        monkeypatch.setenv("OMP_NUM_THREADS", value)
        assert face_hessians.default_threads() == cpus
    monkeypatch.delenv("OMP_NUM_THREADS")
    assert face_hessians.default_threads() == cpus


def _planar_energy(J, w=0.3, eps=0.2):
    """``Psi = N / chi``: ``N = (1 - w) |J|^2 / 2 + w (det J^2 + 1) / 2`` over the regularized
    determinant ``chi = (det J + sqrt(eps^2 + det J^2)) / 2`` (per (2, 2) matrix), and its
    derivatives in ``I2 = |J|^2`` and ``I3 = det J`` by hand."""
    I2, I3 = (J * J).sum(axis=(1, 2)), np.linalg.det(J)
    r = np.sqrt(eps * eps + I3 * I3)
    c, c1, c2 = 0.5 * (I3 + r), 0.5 * (1 + I3 / r), 0.5 * eps * eps / r ** 3
    N = 0.5 * (1 - w) * I2 + 0.5 * w * (I3 * I3 + 1)
    d = dict(d2=0.5 * (1 - w) / c, d3=w * I3 / c - N * c1 / c ** 2, d22=np.zeros_like(I3),
             d23=-0.5 * (1 - w) * c1 / c ** 2,
             d33=w / c - 2 * w * I3 * c1 / c ** 2 - N * c2 / c ** 2 + 2 * N * c1 ** 2 / c ** 3)
    return N / c, d


def test_invariant_hessians_are_the_second_differences_and_their_positive_part():
    """Unprojected: the second central differences of the energy in ``J`` (inverted faces
    among them); projected: :func:`positive_part` of that (a numerical eigendecomposition)."""
    rng = np.random.default_rng(3)
    J = rng.standard_normal((200, 2, 2)) * rng.uniform(0.05, 3.0, (200, 1, 1))
    assert (np.linalg.det(J) < 0).sum() > 50
    _, d = _planar_energy(J)
    H = invariant_hessians(J, **d, project=False)
    h = 1e-4 * np.sqrt((J * J).sum(axis=(1, 2)))[:, None, None]  # per face, to its scale
    basis, size = np.eye(4).reshape(4, 2, 2), np.abs(H).max(axis=(1, 2))
    for a in range(4):
        for b in range(4):
            pp, pm, mp, mm = (_planar_energy(J + h * (sa * basis[a] + sb * basis[b]))[0]
                              for sa, sb in ((1, 1), (1, -1), (-1, 1), (-1, -1)))
            fd = (pp - pm - mp + mm) / (4 * h[:, 0, 0] ** 2)
            assert np.all(np.abs(H[:, a, b] - fd) <= 1e-4 * size)
    P = invariant_hessians(J, **d)
    assert np.allclose(P, positive_part(H), rtol=0, atol=1e-12 * np.abs(H).max())

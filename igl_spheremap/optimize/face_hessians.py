"""Per-face Hessians of the conformal-distortion energy on the tangent planes, made positive
semidefinite: the metric of :class:`igl_spheremap.optimize.conformal_distortion.NewtonMetric`.

A face's term is ``E_f = c_f / d_f`` (:mod:`igl_spheremap.optimize.conformal_distortion`;
``d_f`` is the signed volume ``s_f``, less the guard margin on a guarded face, whose
derivatives are those of ``s_f`` up to the unit roundoff).  Its Hessian in the positions
``(U_i, U_j, U_k)`` is::

    H = Hess(c) / d - (grad c grad s^T + grad s grad c^T) / d^2 + 2 c grad s grad s^T / d^3
        - (c / d^2) Hess(s),

here restricted to the tangent planes of the three vertices (a 6 x 6 matrix in the bases
of :func:`igl_spheremap.mesh.frames.tangent_bases`).  ``Hess(c)`` is the cotangent stencil of
the face times the identity; ``Hess(s)`` of ``s = det[U_i, U_j, U_k]`` has the blocks
``d^2 s / dU_a dU_b = +-[U_c]_x`` (``c`` the third corner).  The first three terms are
positive semidefinite (Cauchy-Schwarz for the quadratic form ``c``); with the last one,
for a face similar to its input, the rank-one terms cancel and ``Hess(c) - (c / s) Hess(s)``
is the least-squares conformal stencil of the face (Lévy, Petitjean, Ray, Maillot, "Least
squares conformal maps", SIGGRAPH 2002): no stiffness for the similarities of the face,
which is what a conformal map changes from face to face.  The last term is indefinite
elsewhere, so each face's matrix has its negative eigenvalues set to zero (projected
Newton: Teran, Sifakis, Irving, Fedkiw, "Robust quasistatic finite elements and flesh
simulation", SCA 2005; as used for distortion energies by Smith, De Goes, Kim,
"Analytic eigensystems for isotropic distortion energies", ACM TOG 38(1), 2019).

:func:`invariant_hessians` does the same in closed form for the planar energies of a 2 x 2
Jacobian that depend on ``|J|^2`` and ``det J`` alone (the untangling energy of
:mod:`igl_spheremap.folding.untangled_disk`).

:func:`projected_tangent_hessians` is the two steps for the metric's set-up, the faces split
into chunks that run in threads: each face's block depends on that face alone, and numpy's
batched ``eigh`` and elementwise arithmetic release the interpreter lock, so a set-up uses
the cores Algorithm 1's other steps leave idle, with the same blocks to the bit.
"""

import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from ..mesh.arrays import cross_rows, rowdot


def _stencil(lam):
    """``Hess(c)`` per face as a (m, 3, 3) array over the corners (times the 3x3 identity)."""
    Lc = np.zeros((lam.shape[0], 3, 3))
    for k in range(3):
        j, l = (k + 1) % 3, (k + 2) % 3
        w = 2.0 * lam[:, k]
        Lc[:, j, j] += w
        Lc[:, l, l] += w
        Lc[:, j, l] -= w
        Lc[:, l, j] -= w
    return Lc


def tangent_hessians(F, lam, U, c, s, Q, e, frames):
    """The 6 x 6 Hessian of ``c_f / s_f`` on the tangent planes of each face's corners.

    Parameters
    ----------
    F : (m, 3) int64 array
    lam : (m, 3) float64 array
        The corner weights of the energy.
    U : (n, 3) float64 array
    c, s : (m,) float64 arrays
        The numerators and signed volumes at ``U``.
    Q, e : lists of three (3, m) arrays
        The corners and opposite edges (``ConformalDistortionEnergy.terms``).
    frames : tuple of two (n, 3) arrays
        :func:`igl_spheremap.mesh.frames.tangent_bases` of ``U`` (its two columns).

    Returns
    -------
    (m, 6, 6) float64 array
        Row ``2 a + i``: corner ``a``, tangent ``t_i``.
    """
    m = s.size
    T = [[frames[i][F[:, a]] for i in range(2)] for a in range(3)]  # T[a][i]: (m, 3)
    Lc = _stencil(lam)
    Qm = [q.T for q in Q]
    em = [x.T for x in e]
    gc, gs = np.zeros((m, 6)), np.zeros((m, 6))
    for a in range(3):
        b, d = (a + 1) % 3, (a + 2) % 3
        dc = 2.0 * (lam[:, b, None] * em[b] - lam[:, d, None] * em[d])
        ds = cross_rows(Qm[a], em[a]) - cross_rows(em[d], em[b])
        for i in range(2):
            gc[:, 2 * a + i] = rowdot(T[a][i], dc)
            gs[:, 2 * a + i] = rowdot(T[a][i], ds)
    H = np.zeros((m, 6, 6))
    for a in range(3):
        for b in range(3):
            if a == b:
                for i in range(2):
                    H[:, 2 * a + i, 2 * a + i] = Lc[:, a, a] / s
                continue
            third = 3 - a - b
            sign = 1.0 if b == (a + 1) % 3 else -1.0
            for j in range(2):
                cross = cross_rows(T[b][j], Qm[third])
                for i in range(2):
                    H[:, 2 * a + i, 2 * b + j] = (Lc[:, a, b] * rowdot(T[a][i], T[b][j]) / s
                                                  - sign * c / (s * s) * rowdot(T[a][i], cross))
    H -= (gc[:, :, None] * gs[:, None, :] + gs[:, :, None] * gc[:, None, :]) / (s * s)[:, None, None]
    H += (2.0 * c / s ** 3)[:, None, None] * gs[:, :, None] * gs[:, None, :]
    return H


#: Fewest faces per thread of :func:`projected_tangent_hessians`: a small mesh's set-up runs
#: in the calling thread.
THREAD_CHUNK = 2048


def default_threads():
    """Threads for per-face work: ``OMP_NUM_THREADS`` where it is set to a positive integer
    (the variable numerical libraries read, and Dask sets to 1 in its workers), else the
    CPUs this process may run on (its affinity where the OS reports one)."""
    value = os.environ.get("OMP_NUM_THREADS", "").strip()
    if value.isdigit() and int(value) > 0:
        return int(value)
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def projected_tangent_hessians(F, lam, U, c, s, Q, e, frames, threads=None):
    """:func:`positive_part` of :func:`tangent_hessians`, the faces in chunks run by threads.

    Parameters
    ----------
    F, lam, U, c, s, Q, e, frames
        As for :func:`tangent_hessians`.
    threads : int, optional
        Most threads (default: :func:`default_threads`); each takes at least
        :data:`THREAD_CHUNK` faces, so a small mesh runs in the calling thread.

    Returns
    -------
    (m, 6, 6) float64 array
        The same blocks, bit for bit, as ``positive_part(tangent_hessians(...))``: every
        block is computed from its own face alone, by the same operations.
    """
    m = s.size
    count = max(1, min(default_threads() if threads is None else int(threads),
                       m // THREAD_CHUNK))
    out = np.empty((m, 6, 6))

    def chunk(part):
        out[part] = positive_part(tangent_hessians(
            F[part], lam[part], U, c[part], s[part], [q[:, part] for q in Q],
            [x[:, part] for x in e], frames))

    bounds = np.linspace(0, m, count + 1).astype(np.int64)
    parts = [slice(int(a), int(b)) for a, b in zip(bounds[:-1], bounds[1:])]
    if count == 1:
        chunk(parts[0])
    else:  # a pool per call: no idle threads left behind for a fork to copy
        with ThreadPoolExecutor(count) as pool:
            list(pool.map(chunk, parts))
    return out


def positive_part(H):
    """``H`` (m, k, k symmetric) with its negative eigenvalues set to zero (per matrix)."""
    H = 0.5 * (H + H.transpose(0, 2, 1))
    scale = np.maximum(np.abs(H).max(axis=(1, 2)), 1e-300)[:, None, None]
    w, P = np.linalg.eigh(H / scale)
    return np.matmul(P * np.maximum(w, 0.0)[:, None, :], P.transpose(0, 2, 1)) * scale


def invariant_hessians(J, d2, d3, d22, d23, d33, project=True):
    """Hessians of a planar energy ``Psi(I2, I3)`` of 2 x 2 Jacobians, made positive
    semidefinite in closed form.

    ``I2 = |J|_F^2`` and ``I3 = det J``; the energy is isotropic, so its Hessian in ``J``
    has the eigenvectors of Smith, De Goes, Kim, "Analytic eigensystems for isotropic
    distortion energies" (ACM TOG 38(1), 2019), here for the signed singular value
    decomposition ``J = U diag(s1, s2) V^T`` (``U``, ``V`` rotations, ``s2 < 0`` on an
    inverted face): the twist ``U [[0, -1], [1, 0]] V^T / sqrt 2`` with eigenvalue
    ``2 Psi_2 + Psi_3``, the flip ``U [[0, 1], [1, 0]] V^T / sqrt 2`` with
    ``2 Psi_2 - Psi_3``, and in the span of ``U diag(1, 0) V^T``, ``U diag(0, 1) V^T`` the
    2 x 2 matrix of ``Psi_22 a a^T + Psi_33 b b^T + Psi_23 (a b^T + b a^T) + 2 Psi_2 I +
    Psi_3 [[0, 1], [1, 0]]`` with ``a = 2 (s1, s2)``, ``b = (s2, s1)`` (the gradients of
    ``I2`` and ``I3``).  Negative eigenvalues are set to zero, as
    :func:`positive_part` does with a numerical eigendecomposition.

    Parameters
    ----------
    J : (f, 2, 2) float64 array
    d2, d3, d22, d23, d33 : (f,) float64 arrays
        ``dPsi/dI2``, ``dPsi/dI3`` and the second derivatives, per face.
    project : bool
        Set the negative eigenvalues to zero (default); False gives the Hessian itself.

    Returns
    -------
    (f, 4, 4) float64 array
        Over ``J`` flattened row by row, ``(J00, J01, J10, J11)``.
    """
    a, b, c, d = J[:, 0, 0], J[:, 0, 1], J[:, 1, 0], J[:, 1, 1]
    e, f, g, h = (a + d) / 2, (a - d) / 2, (c + b) / 2, (c - b) / 2
    q, r = np.hypot(e, h), np.hypot(f, g)
    s1, s2 = q + r, q - r
    a1, a2 = np.arctan2(g, f), np.arctan2(h, e)
    phi, theta = (a2 + a1) / 2, (a2 - a1) / 2  # J = R(phi) diag(s1, s2) R(theta)
    u1 = np.column_stack([np.cos(phi), np.sin(phi)])
    u2 = np.column_stack([-np.sin(phi), np.cos(phi)])
    v1 = np.column_stack([np.cos(theta), -np.sin(theta)])  # the rows of R(theta)
    v2 = np.column_stack([np.sin(theta), np.cos(theta)])

    def outer(u, v):
        return (u[:, :, None] * v[:, None, :]).reshape(-1, 4)

    D1, D2 = outer(u1, v1), outer(u2, v2)
    twist = (outer(u2, v1) - outer(u1, v2)) / np.sqrt(2.0)
    flip = (outer(u2, v1) + outer(u1, v2)) / np.sqrt(2.0)
    # the 2 x 2 block on (D1, D2)
    m11 = 4 * d22 * s1 * s1 + d33 * s2 * s2 + 4 * d23 * s1 * s2 + 2 * d2
    m22 = 4 * d22 * s2 * s2 + d33 * s1 * s1 + 4 * d23 * s1 * s2 + 2 * d2
    m12 = 4 * d22 * s1 * s2 + d33 * s1 * s2 + 2 * d23 * (s1 * s1 + s2 * s2) + d3
    mean, half = (m11 + m22) / 2, np.hypot((m11 - m22) / 2, m12)
    angle = 0.5 * np.arctan2(2 * m12, m11 - m22)  # eigenvector of mean + half
    cs, sn = np.cos(angle)[:, None], np.sin(angle)[:, None]
    modes = [(mean + half, cs * D1 + sn * D2), (mean - half, -sn * D1 + cs * D2),
             (2 * d2 + d3, twist), (2 * d2 - d3, flip)]
    H = np.zeros((J.shape[0], 4, 4))
    for lam, x in modes:
        weight = np.maximum(lam, 0.0) if project else lam
        H += weight[:, None, None] * x[:, :, None] * x[:, None, :]
    return H

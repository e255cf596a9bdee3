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
simulation", SCA 2005; as used for distortion energies by Smith, Goldenthal, Grinspun,
"Analytic eigensystems for isotropic distortion energies", ACM TOG 38(1), 2019).
"""

import numpy as np

from ..mesh.arrays import rowdot


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
        ds = np.cross(Qm[a], em[a]) - np.cross(em[d], em[b])
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
                cross = np.cross(T[b][j], Qm[third])
                for i in range(2):
                    H[:, 2 * a + i, 2 * b + j] = (Lc[:, a, b] * rowdot(T[a][i], T[b][j]) / s
                                                  - sign * c / (s * s) * rowdot(T[a][i], cross))
    H -= (gc[:, :, None] * gs[:, None, :] + gs[:, :, None] * gc[:, None, :]) / (s * s)[:, None, None]
    H += (2.0 * c / s ** 3)[:, None, None] * gs[:, :, None] * gs[:, None, :]
    return H


def positive_part(H):
    """``H`` (m, k, k symmetric) with its negative eigenvalues set to zero (per matrix)."""
    H = 0.5 * (H + H.transpose(0, 2, 1))
    scale = np.maximum(np.abs(H).max(axis=(1, 2)), 1e-300)[:, None, None]
    w, P = np.linalg.eigh(H / scale)
    return np.matmul(P * np.maximum(w, 0.0)[:, None, :], P.transpose(0, 2, 1)) * scale

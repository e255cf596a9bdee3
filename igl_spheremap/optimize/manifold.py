"""The product of unit spheres ``(S^2)^n`` with the lumped L2 product and the Cayley retraction.

A spherical map ``U`` (n, 3) is a point of ``(S^2)^n`` (paper problem (6)); a
tangent vector ``X`` (n, 3) has ``U_i . X_i = 0``.  Inner products are the lumped
L2 products ``<X, Y>_M = sum_i A_i X_i . Y_i`` of paper Eq. 13 with ``A_i`` the
vertex areas of the mesh scaled to total area ``4 pi``.  The retraction is the
closed-form Cayley update of paper Theorem 1 (Eqs. 10-11).
"""

import numpy as np

from ..mesh.arrays import rowdot


def cayley_step(U, H, tau, tangent=False):
    """Closed-form Cayley update ``Y[tau] = alpha U + beta H`` of paper Theorem 1 (Eqs. 10-11).

    Per vertex ``i`` with ``A_i = H_i U_i^T - U_i H_i^T`` (skew-symmetric),
    ``Y_i = (I + tau/2 A_i)^{-1} (I - tau/2 A_i) U_i``.  Theorem 1 turns the 3x3
    solve into scalars: with ``a = U_i . H_i``, ``b = |H_i|^2`` and ``|U_i| = 1``,
    ``alpha = ((1 + tau a / 2)^2 - (tau/2)^2 b) / d``, ``beta = -tau / d`` and
    ``d = 1 + (tau/2)^2 (b - a^2)``.  It is evaluated with the tangential part
    ``G_i = H_i - a U_i`` in place of ``H_i`` (same ``A_i``, so the same ``Y_i``),
    which stays accurate for large ``tau |H_i|``.  ``|Y_i| = |U_i|`` for every ``tau`` and
    ``dY/dtau`` at 0 is ``-(H_i - a U_i)``, minus the Riemannian gradient.

    Parameters
    ----------
    U : (n, 3) float64 array
        Current map, unit rows.
    H : (n, 3) float64 array
        Direction (paper: the L2 gradient ``H = -ΔF``; Algorithm 1 here passes its
        search direction).
    tau : float
        Step size (dimensionless once the mesh has area ``4 pi``).
    tangent : bool
        ``H`` is tangential already (``U_i . H_i = 0`` to rounding, as Algorithm 1's
        projected directions are): skip the projection (one pass over the arrays
        instead of three).

    Returns
    -------
    Y : (n, 3) float64 array
        Unit rows (to rounding).
    """
    # A_i depends only on the tangential part of H_i (the normal part cancels in
    # H U^T - U H^T), so Theorem 1 is evaluated with G = H - (U.H) U, a = 0:
    # exact in exact arithmetic and free of the cancellation that a large
    # normal component causes in alpha when tau |H| is large.
    if tangent:
        G = H
    else:
        G = H - np.einsum("ij,ij->i", U, H)[:, None] * U
        G -= np.einsum("ij,ij->i", U, G)[:, None] * U  # second pass: normal residue of rounding
    s2b = (0.5 * tau) ** 2 * rowdot(G, G)
    d = 1.0 + s2b
    return ((1.0 - s2b) / d)[:, None] * U - (tau / d)[:, None] * G


class SphereProduct:
    """``(S^2)^n`` with the lumped L2 product of paper Eq. 13.

    Parameters
    ----------
    area : (n,) float64 array
        Vertex areas ``A_i`` (mesh scaled to total area ``4 pi``).
    """

    def __init__(self, area):
        self.area = np.asarray(area, dtype=np.float64)

    def tangent(self, U, X):
        """Tangential part ``X_i - (U_i . X_i) U_i`` of ``X`` at ``U`` (a new array)."""
        return X - rowdot(U, X)[:, None] * U

    def inner(self, X, Y):
        """``<X, Y>_M = sum_i A_i X_i . Y_i`` (float)."""
        return float(np.vdot(X * self.area[:, None], Y))

    def retract(self, U, X, tau):
        """The point ``tau`` along the Cayley curve of Theorem 1 from ``U`` in direction ``-X``.

        ``X`` must be tangential (Algorithm 1's directions are projected).
        """
        return cayley_step(U, X, tau, tangent=True)

"""The curvilinear (Cayley) update on the product of unit spheres, paper Theorem 1."""

import numpy as np


def cayley_step(U, H, tau):
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
        Euclidean (L2) gradient of the energy at ``U`` (paper: ``H = -ΔF``).
    tau : float
        Step size (dimensionless once the mesh has area ``4 pi``).

    Returns
    -------
    Y : (n, 3) float64 array
        Unit rows (to rounding).
    """
    # A_i depends only on the tangential part of H_i (the normal part cancels in
    # H U^T - U H^T), so Theorem 1 is evaluated with G = H - (U.H) U, a = 0:
    # exact in exact arithmetic and free of the cancellation that a large
    # normal component causes in alpha when tau |H| is large.
    G = H - np.einsum("ij,ij->i", U, H)[:, None] * U
    G -= np.einsum("ij,ij->i", U, G)[:, None] * U  # second pass: normal residue of rounding
    s2b = (0.5 * tau) ** 2 * np.einsum("ij,ij->i", G, G)
    d = 1.0 + s2b
    return ((1.0 - s2b) / d)[:, None] * U - (tau / d)[:, None] * G

"""Geodesics of the unit sphere, row by row: angles, great-circle interpolation, and the
exponential and logarithm maps between points and tangent vectors."""

import numpy as np

from ..mesh.arrays import cross_rows, rowdot, unit_rows


def angles(A, B):
    """Angles between the rows of ``A`` and ``B`` ((k,) float64, radians; exact near 0)."""
    return np.arctan2(np.linalg.norm(cross_rows(A, B), axis=1), rowdot(A, B))


def slerp(A, B, t):
    """Points the fraction ``t`` of the way from ``A`` to ``B`` along great circles ((k, 3))."""
    if t >= 1.0:
        return B.copy()
    theta = angles(A, B)
    s = np.sin(theta)
    safe = s > 1e-12
    wa = np.where(safe, np.sin((1.0 - t) * theta) / np.where(safe, s, 1.0), 1.0 - t)
    wb = np.where(safe, np.sin(t * theta) / np.where(safe, s, 1.0), t)
    return unit_rows(wa[:, None] * A + wb[:, None] * B)


def log_map(A, B):
    """Tangent vectors at the rows of ``A`` toward ``B``, of length the angle ((k, 3), radians)."""
    theta = angles(A, B)
    T = B - rowdot(A, B)[:, None] * A
    nt = np.linalg.norm(T, axis=1)
    return np.where(nt[:, None] > 0, T * (theta / np.where(nt > 0, nt, 1.0))[:, None], 0.0)


def exp_map(X, d):
    """``exp_X(d)`` row by row after projecting ``d`` on the tangent planes ((n, 3) unit rows)."""
    d = d - rowdot(d, X)[:, None] * X
    r = np.linalg.norm(d, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return (np.cos(r)[:, None] * X
                + np.where(r[:, None] > 0, np.sin(r)[:, None] * d / r[:, None], 0.0))

"""Per-triangle and per-point tangent frames: the 2-D coordinates that distortion measures use."""

import numpy as np

from .arrays import cross_rows, rowdot


def triangle_frames(V, F):
    """Each triangle's corners in its own 2-D frame, the inverse edge matrices and the areas.

    Triangle ``(a, b, c)`` with edges ``e1 = b - a``, ``e2 = c - a`` has the frame
    coordinates ``a -> (0, 0)``, ``b -> (|e1|, 0)``, ``c -> (e1.e2 / |e1|, 2 area / |e1|)``.
    The Jacobian of the linear map of the triangle onto a triangle with edges
    ``E = [x_b - x_a, x_c - x_a]`` (3 x 2) is ``J = E @ Dinv``.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int array
        Non-degenerate triangles.

    Returns
    -------
    corners : (m, 3, 2) float64 array
        Frame coordinates of the three corners (same units as ``V``).
    Dinv : (m, 2, 2) float64 array
        Inverse of the edge matrix ``[[|e1|, e1.e2/|e1|], [0, 2 area/|e1|]]``.
    area : (m,) float64 array
    """
    e1 = V[F[:, 1]] - V[F[:, 0]]
    e2 = V[F[:, 2]] - V[F[:, 0]]
    l1 = np.linalg.norm(e1, axis=1)
    dbl = np.linalg.norm(cross_rows(e1, e2), axis=1)
    corners = np.zeros((F.shape[0], 3, 2))
    corners[:, 1, 0] = l1
    corners[:, 2, 0] = rowdot(e1, e2) / l1
    corners[:, 2, 1] = dbl / l1
    D = np.stack([corners[:, 1], corners[:, 2]], axis=2)
    return corners, np.linalg.inv(D), dbl / 2.0


def tangent_bases(N):
    """Orthonormal bases (n, 3, 2) of the planes with the unit normals ``N`` (n, 3).

    The columns ``t1, t2`` satisfy ``t1 x t2 = N`` (right-handed about ``N``).
    """
    a = np.where(np.abs(N[:, :1]) < 0.9, np.array([[1.0, 0, 0]]), np.array([[0, 1.0, 0]]))
    t1 = cross_rows(N, a)
    t1 /= np.linalg.norm(t1, axis=1, keepdims=True)
    t2 = cross_rows(N, t1)
    return np.stack([t1, t2], axis=2)

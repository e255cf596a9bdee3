"""Floater's mean value weights of a triangle mesh's directed edges."""

import igl
import numpy as np
import scipy.sparse as sp


def mean_value_weights(V, F, E):
    """Mean value weights ``w_ij`` and ``w_ji`` of the edges ``E`` of a triangle mesh.

    ``w_ij = (tan(a / 2) + tan(b / 2)) / |x_i - x_j|`` with ``a`` and ``b`` the
    angles at ``i`` of the faces on either side of edge ``ij`` (one face on a
    boundary edge).  Positive for any mesh without degenerate angles, so a
    Tutte embedding with these weights and a convex boundary is fold-free (M. S.
    Floater, "Mean value coordinates", CAGD 20(1), 2003, Eq. 3.1; Tutte's theorem
    in Floater's form, "One-to-one piecewise linear mappings over
    triangulations", Math. Comp. 72, 2003).  Not symmetric.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int64 array
    E : (e, 2) int array
        Edges ``(i, j)`` of ``F``.

    Returns
    -------
    (e, 2) float64 array
        Column 0: ``w_ij`` (row ``i`` of a Tutte system), column 1: ``w_ji``.
    """
    ang = igl.internal_angles(V, F)  # (m, 3): the angle at corner c
    n = V.shape[0]
    rows, cols, vals = [], [], []
    for c in range(3):
        i, j, k = F[:, c], F[:, (c + 1) % 3], F[:, (c + 2) % 3]
        t = np.tan(ang[:, c] / 2.0)
        rows += [i, i]  # the angle at i lies between its edges ij and ik
        cols += [j, k]
        vals += [t, t]
    T = sp.coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(n, n)).tocsr()
    length = np.linalg.norm(V[E[:, 0]] - V[E[:, 1]], axis=1)
    wij = np.asarray(T[E[:, 0], E[:, 1]]).ravel() / length
    wji = np.asarray(T[E[:, 1], E[:, 0]]).ravel() / length
    return np.column_stack([wij, wji])

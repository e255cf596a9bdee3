"""Intrinsic mollification of a mesh's edge lengths (Sharp, Crane, "A Laplacian for
nonmanifold triangle meshes", SGP 2020).

A face with a corner near 180 degrees (a vertex on, or nearly on, the opposite edge: STL
exports of CAD parts close T-junctions this way) has almost no area, and a shape that
no map of the sphere can copy without degenerating its image.  Adding one small length
``eps`` to every edge makes every triangle inequality hold with a slack of at least
``delta``: the degenerate faces become thin but honest triangles, and a mesh whose faces
all have that slack already is left exactly as it is (``eps = 0``).
"""

import igl
import numpy as np

#: ``delta`` as a share of the mean edge length: the default of Sharp and Crane's robust
#: Laplacian (``mollify_factor`` of the ``robust_laplacian`` package).
MOLLIFY_FACTOR = 1e-5


def mollified_edge_lengths(V, F, factor=MOLLIFY_FACTOR):
    """Edge lengths of each face, each raised by the least ``eps >= 0`` that gives every face
    a triangle-inequality slack of at least ``factor`` times the mean edge length.

    Parameters
    ----------
    V : (n, 3) float64 array
        Vertex positions (any unit).
    F : (m, 3) int64 array
        Triangles.
    factor : float
        ``delta`` over the mean edge length (:data:`MOLLIFY_FACTOR`), ``>= 0``.

    Returns
    -------
    lengths : (m, 3) float64 array
        ``igl.edge_lengths`` (column ``k``: the edge opposite corner ``k``) plus ``eps``.
    eps : float
        What was added, in the unit of ``V`` (0 when every face had the slack).

    Notes
    -----
    The slack of a face is ``min_k (l_i + l_j - l_k)``; adding ``eps`` to all three
    lengths raises it by ``eps``, so ``eps = max(0, delta - least slack)``.  A change of
    ``eps`` in every length moves no angle of a face of edge ``L`` by more than about
    ``eps / L`` radians.
    """
    lengths = igl.edge_lengths(np.asarray(V, dtype=np.float64), np.asarray(F, dtype=np.int64))
    eps = max(0.0, factor * float(lengths.mean()) - float(triangle_slack(lengths).min()))
    return lengths + eps, eps


def triangle_slack(lengths):
    """Per face, the slack of its triangle inequality, ``min_k (l_i + l_j - l_k)``.

    Parameters
    ----------
    lengths : (m, 3) float64 array
        Edge lengths of each face (any order).

    Returns
    -------
    (m,) float64 array
        ``l_0 + l_1 + l_2 - 2 max_k l_k``, in the unit of ``lengths``: 0 for a face of zero
        area, negative for lengths of no triangle.
    """
    return lengths[:, 0] + lengths[:, 1] + lengths[:, 2] - 2.0 * lengths.max(axis=1)

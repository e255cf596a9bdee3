"""The Gauss map, the paper's initial map (Definition 1)."""

import igl
import numpy as np


def gauss_map(V, F):
    """Gauss map: each vertex to its unit normal (paper Definition 1, Section 3.2).

    Normals are libigl's area-weighted ``per_vertex_normals``.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int array
        Outward-oriented closed mesh.

    Returns
    -------
    U : (n, 3) float64 array
        Unit vectors.
    """
    N = igl.per_vertex_normals(np.asarray(V, dtype=np.float64), np.asarray(F, dtype=np.int64),
                               igl.PER_VERTEX_NORMALS_WEIGHTING_TYPE_AREA)
    return N / np.linalg.norm(N, axis=1, keepdims=True)

"""The Gauss map, the paper's initial map (Definition 1)."""

import igl
import numpy as np

from .validation import validate_mesh


def gauss_map(V, F):
    """Gauss map: each vertex to its unit normal (paper Definition 1, Section 3.2).

    Normals are libigl's area-weighted ``per_vertex_normals`` of the outward
    oriented mesh (:func:`igl_spheremap.validate_mesh` orients it).

    Parameters
    ----------
    V : (n, 3) array_like of float
    F : (m, 3) array_like of int
        A closed, connected, genus-0 triangle mesh.

    Returns
    -------
    U : (n, 3) float64 array
        Unit vectors, indexed like ``V`` (an unreferenced vertex gets the normal
        of its nearest surface vertex).

    Raises
    ------
    MeshError
        If the mesh is invalid (:func:`igl_spheremap.validate_mesh`).
    """
    mesh = validate_mesh(V, F)
    return mesh.to_input(vertex_normals(mesh.V, mesh.F))


def vertex_normals(V, F):
    """Unit area-weighted vertex normals of a validated, outward-oriented mesh ((n, 3) float64)."""
    N = igl.per_vertex_normals(V, F, igl.PER_VERTEX_NORMALS_WEIGHTING_TYPE_AREA)
    return N / np.linalg.norm(N, axis=1, keepdims=True)

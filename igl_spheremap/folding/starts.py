"""Initial maps of Algorithm 2: the Gauss map (the paper's, Definition 1) and the central projection."""

import igl
import numpy as np

from ..mesh.validate import validate_mesh
from ..sphere.folds import count_folds


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


def central_projection(V, F, area):
    """``(V - c) / |V - c|`` with ``c`` the area centroid, or None when that folds a face.

    Fold-free exactly when the surface is star-shaped about ``c`` (e.g. convex).

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int64 array
        Outward oriented.
    area : (n,) float64 array
        Vertex areas (the weights of the centroid).

    Returns
    -------
    (n, 3) float64 array or None
    """
    P = V - (area @ V) / area.sum()
    norm = np.linalg.norm(P, axis=1, keepdims=True)
    if not np.all(norm > 0):
        return None
    U = P / norm
    return None if count_folds(F, U) else U

"""Initial maps of Algorithm 2: the Gauss map (the paper's, Definition 1), and the central
projection from the mesh's kernel, fold-free by construction for star-shaped meshes."""

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


def kernel_center(V, F):
    """The point of the mesh's kernel farthest from every face plane, or None if the kernel is empty.

    The central projection from a point ``p`` has ``det[U_i, U_j, U_k]`` of the
    sign of ``n_f . (V_i - p)`` (``n_f`` the face normal): every image face is
    positive exactly when ``p`` lies strictly inside every face's plane, in the
    open kernel of the polyhedron (the mesh is star-shaped about ``p``).  The
    linear program maximizes the smallest distance ``t`` of ``p`` to the face
    planes (a Chebyshev centre of the kernel; HiGHS through ``scipy.optimize.linprog``).

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int64 array
        Closed mesh, oriented outward.

    Returns
    -------
    p : (3,) float64 array or None
        The centre, when the optimum ``t`` is positive.
    t : float
        The optimum: the distance of ``p`` to the nearest face plane (<= 0: the
        mesh is not star-shaped).
    """
    from scipy.optimize import linprog

    Vi, Vj, Vk = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    N = np.cross(Vj - Vi, Vk - Vi)
    length = np.linalg.norm(N, axis=1)
    ok = length > 0
    N = N[ok] / length[ok, None]
    scale = float(np.abs(V).max())
    res = linprog(c=[0.0, 0.0, 0.0, -1.0], A_ub=np.column_stack([N, np.ones(N.shape[0])]),
                  b_ub=np.einsum("ij,ij->i", N, Vi[ok]),
                  bounds=[(-10 * scale, 10 * scale)] * 3 + [(None, scale)], method="highs")
    if res.status != 0:
        return None, -np.inf
    p, t = res.x[:3], float(res.x[3])
    return (p if t > 0 else None), t


def central_projection(V, F):
    """``(V - p) / |V - p|`` from the kernel centre ``p`` (:func:`kernel_center`), or None.

    Fold-free by construction when the mesh is star-shaped (a convex hull, say);
    it maps straight lines to great circles, so the needle triangles and
    fan-triangulated flat faces of CAD meshes keep their orientation, which a
    smooth (conformal) map bends.  None when the kernel is empty or the
    projection folds in floating point.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int64 array
        Outward oriented.

    Returns
    -------
    (n, 3) float64 array or None
    """
    p, _ = kernel_center(V, F)
    if p is None:
        return None
    P = V - p
    U = P / np.linalg.norm(P, axis=1, keepdims=True)
    return None if count_folds(F, U) else U

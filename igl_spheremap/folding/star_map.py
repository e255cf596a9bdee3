"""Weighted Laplace-Beltrami eigen-projection: the star map of paper Section 4.2."""

import igl
import numpy as np
import scipy.sparse as sp

from ..errors import plural
from ..mesh.arrays import as_points
from ..mesh.operators import laplacian, signed_volumes, to_sphere_area, vertex_areas
from ..mesh.validate import validate_mesh


def weighted_eigenfunctions(L, B, k=3, sigma=-1e-3):
    """First ``k`` nontrivial eigenpairs of ``-L x = lambda B x`` (paper Eq. 27).

    Solved with ``scipy.sparse.linalg.eigsh`` in shift-invert mode around a
    slightly negative ``sigma`` (so ``-L - sigma B`` is positive definite and is
    factorized once) from a fixed start vector, so results are deterministic.

    Parameters
    ----------
    L : (n, n) sparse matrix
        Stiffness (negative semidefinite Laplacian, ``A = -L`` of Eq. 26).
    B : (n, n) sparse matrix
        Symmetric positive definite weighted mass matrix ``B_u`` of Eq. 26.
    k : int
        Number of nontrivial eigenpairs.
    sigma : float
        Shift (< 0).

    Returns
    -------
    lam : (k,) float64 array
        Eigenvalues ``lambda_1 <= ... <= lambda_k``.
    Phi : (n, k) float64 array
        ``B``-orthonormal eigenvectors.

    Raises
    ------
    RuntimeError
        If the eigensolver fails or returns non-finite values.
    """
    import scipy.sparse.linalg as sla  # ARPACK only when a star map is built

    n = L.shape[0]
    v0 = np.ones(n) + 1e-3 * np.cos(np.arange(n))
    try:
        lam, X = sla.eigsh(-L.tocsc(), k=k + 1, M=B.tocsc(), sigma=sigma, which="LM", v0=v0)
    except (sla.ArpackNoConvergence, sla.ArpackError, RuntimeError) as err:
        raise RuntimeError(f"weighted Laplace-Beltrami eigensolver failed: {err}") from err
    if not (np.all(np.isfinite(lam)) and np.all(np.isfinite(X))):
        raise RuntimeError("weighted Laplace-Beltrami eigensolver returned non-finite values")
    order = np.argsort(lam)
    lam, X = lam[order], X[:, order]
    return lam[1:], X[:, 1:]


def star_map(V, F, U, *, return_details=False):
    """Star map of the weighted Laplace-Beltrami eigenfunctions (paper Theorem 2, Algorithm 2).

    From the current map ``U`` the conformal factor ``e^{2u}`` (Eq. 14) weights
    the mass matrix ``B_u`` (Eq. 26, lumped: ``B_u = diag(e^{2u_i} A_i)``, which
    is the barycentric mass of the image ``(U, F)``).  The first three
    nontrivial eigenvectors ``Phi^u`` of ``A x = lambda B_u x`` (Eq. 27, ``A = -L``
    the stiffness of :func:`igl_spheremap.mesh.operators.laplacian`), centered by
    ``c = ∫ Phi^u dM / |M|`` (input vertex areas) and normalized, give the star
    map.  An eigenbasis may be a reflection (then every face of the star map is
    inverted): if the total signed image volume is negative, the first
    coordinate is negated, which makes the star map orientation preserving.

    Parameters
    ----------
    V : (n, 3) array_like of float
    F : (m, 3) array_like of int
        A closed, connected, genus-0 triangle mesh (validated and oriented
        outward by :func:`igl_spheremap.validate_mesh`).
    U : (n, 3) array_like of float
        Current spherical map (defines the conformal factor), indexed like ``V``.
    return_details : bool
        Also return ``(Phi, eigenvalues, reflected)``.

    Returns
    -------
    S : (n, 3) float64 array
        Unit vectors, indexed like ``V``.
    Phi : (n, 3) float64 array
        Only with ``return_details``: the eigenfunctions (``B_u``-orthonormal).
    lam : (3,) float64 array
        Only with ``return_details``: eigenvalues for the mesh scaled to area ``4 pi``
        (2 for each on a round sphere).
    reflected : bool
        Only with ``return_details``: whether the eigenbasis was a reflection.

    Raises
    ------
    MeshError
        If the mesh is invalid.
    ValueError
        If ``U`` is not an (n, 3) array of finite numbers.
    RuntimeError
        If the eigensolver fails, or a vertex lands on the center ``c``.
    """
    mesh = validate_mesh(V, F)
    U = mesh.from_input(as_points(U, "U", rows=mesh.n_input))
    L = laplacian(mesh.V, mesh.F)
    S, Phi, lam, reflected = star_map_of(mesh.F, U, L, vertex_areas(mesh.V, mesh.F))
    S, Phi = mesh.to_input(S), mesh.to_input(Phi)
    return (S, Phi, lam, reflected) if return_details else S


def star_map_of(F, U, L, area):
    """:func:`star_map` on prepared operators of a validated mesh.

    Parameters
    ----------
    F : (m, 3) int64 array
        Outward faces.
    U : (n, 3) float64 array
        Current map.
    L : (n, n) sparse matrix
        Stiffness Laplacian (negative semidefinite).
    area : (n,) float64 array
        Vertex areas of the mesh (any scale).

    Returns
    -------
    S, Phi, lam, reflected
        As :func:`star_map` with ``return_details``.
    """
    B = igl.massmatrix(np.asarray(U, dtype=np.float64), F, igl.MASSMATRIX_TYPE_BARYCENTRIC)
    b = np.asarray(B.diagonal())
    b = to_sphere_area(np.maximum(b, 1e-300))
    lam, Phi = weighted_eigenfunctions(L, sp.diags(b), k=3)
    c = (area @ Phi) / area.sum()
    X = Phi - c
    r = np.linalg.norm(X, axis=1)
    if not np.all(r > 0):
        k = int(np.count_nonzero(r == 0))
        raise RuntimeError(f"{plural(k, 'vertex', 'vertices')} of Phi^u "
                           f"{'coincides' if k == 1 else 'coincide'} with its center")
    S = X / r[:, None]
    reflected = bool(np.sum(signed_volumes(F, S)) < 0)
    if reflected:
        S[:, 0] = -S[:, 0]
        Phi = Phi.copy()
        Phi[:, 0] = -Phi[:, 0]
    return S, Phi, lam, reflected

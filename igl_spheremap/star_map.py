"""Weighted Laplace-Beltrami eigen-projection: the star map of paper Section 4.2."""

import igl
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from .metrics import signed_image_volumes
from .operators import laplacian, vertex_areas


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


def star_map(V, F, U, *, L=None, area=None, return_details=False):
    """Star map of the weighted Laplace-Beltrami eigenfunctions (paper Theorem 2, Algorithm 2).

    From the current map ``U`` the conformal factor ``e^{2u}`` (Eq. 14) weights
    the mass matrix ``B_u`` (Eq. 26, lumped: ``B_u = diag(e^{2u_i} A_i)``, which
    is the barycentric mass of the image ``(U, F)``).  The first three
    nontrivial eigenvectors ``Phi^u`` of ``A x = lambda B_u x`` (Eq. 27), centered
    by ``c = ∫ Phi^u dM / |M|`` and normalized, give the star map.  An
    eigenbasis may be a reflection (then every face of the star map is
    inverted): if the total signed image volume is negative, the first
    coordinate is negated, which makes the star map orientation preserving.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int array
        Closed genus-0 mesh, outward oriented.
    U : (n, 3) float64 array
        Current spherical map (defines the conformal factor).
    L : (n, n) sparse matrix, optional
        Stiffness Laplacian; default ``igl_spheremap.operators.laplacian(V, F)``.
    area : (n,) float64 array, optional
        Vertex areas of ``V`` (any scale); default barycentric areas.
    return_details : bool
        Also return ``(Phi, eigenvalues, reflected)``.

    Returns
    -------
    S : (n, 3) float64 array
        Unit vectors.
    Phi : (n, 3) float64 array
        Only with ``return_details``: the eigenfunctions (``B_u``-orthonormal).
    lam : (3,) float64 array
        Only with ``return_details``: eigenvalues for the mesh scaled to area ``4 pi``
        (2 for each on a round sphere).
    reflected : bool
        Only with ``return_details``: whether the eigenbasis was a reflection.

    Raises
    ------
    RuntimeError
        If the eigensolver fails, or a vertex lands on the center ``c``.
    """
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    if L is None:
        L = laplacian(V, F)
    if area is None:
        area = vertex_areas(V, F)
    B = igl.massmatrix(np.asarray(U, dtype=np.float64), F, igl.MASSMATRIX_TYPE_BARYCENTRIC)
    b = np.asarray(B.diagonal())
    b = np.maximum(b, 1e-300)
    b *= 4.0 * np.pi / b.sum()
    lam, Phi = weighted_eigenfunctions(L, sp.diags(b), k=3)
    c = (area @ Phi) / area.sum()
    X = Phi - c
    r = np.linalg.norm(X, axis=1)
    if not np.all(r > 0):
        raise RuntimeError(f"{np.count_nonzero(r == 0)} vertices of Phi^u coincide with its center")
    S = X / r[:, None]
    reflected = bool(np.sum(signed_image_volumes(F, S)) < 0)
    if reflected:
        S[:, 0] = -S[:, 0]
        Phi = Phi.copy()
        Phi[:, 0] = -Phi[:, 0]
    if return_details:
        return S, Phi, lam, reflected
    return S

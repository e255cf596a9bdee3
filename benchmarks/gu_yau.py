"""Gu-Yau-style baseline for the benchmarks (NOT part of the library).

The comparator of the paper's Tables 2 and 3 is the variational method of Gu
and Yau (Commun Inf Syst 2(2):121-146, 2002; the genus-0 algorithm as written
up in Gu, Wang, Chan, Thompson, Yau, IEEE TMI 23(8), 2004): plain gradient
descent of the harmonic energy in the tangent spaces of the sphere with a fixed
step, each step followed by the projection of every vertex back onto the
sphere and by the Gu-Yau normalization (subtract the area-weighted centroid of
the image, then project again).  This file is our own re-implementation of
that scheme, written only so that compare.py can show what Algorithm 1 is
faster than; it reuses the same discretisation as the library (cotangent
Laplacian, lumped barycentric vertex areas of the mesh scaled to area 4 pi) and
the same stopping rule (RMS Riemannian gradient <= gtol), so iteration counts
and times are comparable.
"""

import time
from dataclasses import dataclass

import igl
import numpy as np

from igl_spheremap.mesh.operators import to_sphere_area


@dataclass
class GuYauResult:
    """Outcome of :func:`gu_yau_harmonic_map`.

    Attributes
    ----------
    U : (n, 3) float64 array
        Final map, unit rows.
    converged : bool
        The RMS Riemannian gradient reached ``gtol``.
    message : str
        Why the iteration stopped (converged, iteration cap or time cap).
    nit : int
        Gradient steps taken.
    energy : float
        Final harmonic energy ``-1/2 tr(U^T L U)`` (``4 pi`` for a conformal bijection).
    grad_norm : float
        Final RMS Riemannian gradient ``sqrt(sum_i A_i |P_i (M^-1 L U)_i|^2 / 4 pi)``.
    step : float
        The fixed step size used (dimensionless: the mesh is scaled to area 4 pi).
    seconds : float
        Wall time.
    """

    U: np.ndarray
    converged: bool
    message: str
    nit: int
    energy: float
    grad_norm: float
    step: float
    seconds: float


def stable_step(L, area):
    """The textbook fixed step ``1 / lambda_max`` of gradient descent on the energy.

    In the lumped L2 metric the energy's gradient is Lipschitz with constant
    ``lambda_max``, the largest eigenvalue of ``-L x = lambda M x``; the explicit
    step is stable below ``2 / lambda_max`` and ``1 / lambda_max`` is the usual
    fixed choice.  ``lambda_max`` comes from ``scipy.sparse.linalg.eigsh`` on
    the symmetric ``M^{-1/2} (-L) M^{-1/2}`` (loose tolerance, then 2 %
    margin); if that fails, from Gershgorin's bound
    ``max_i (|L_ii| + sum_{j != i} |L_ij|) / A_i`` (at most twice too large).

    Parameters
    ----------
    L : (n, n) sparse matrix
        Cotangent Laplacian (``igl.cotmatrix``), negative semidefinite.
    area : (n,) float64 array
        Vertex areas (mesh scaled to area ``4 pi``).

    Returns
    -------
    float
    """
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla
    L = sp.csr_matrix(L)
    d = sp.diags(1.0 / np.sqrt(area))
    try:
        lam = spla.eigsh(-(d @ L @ d), k=1, which="LA", tol=1e-3,
                         return_eigenvectors=False)[0] * 1.02
    except (spla.ArpackNoConvergence, spla.ArpackError):
        lam = np.max(np.asarray(abs(L).sum(axis=1)).ravel() / area)
    return float(1.0 / lam)


def gu_yau_harmonic_map(V, F, U0, *, step=None, gtol=1e-5, max_iter=1_000_000,
                        max_seconds=60.0):
    """Harmonic map to the sphere by Gu-Yau-style tangential gradient descent.

    Each iteration, with ``M`` the lumped vertex areas ``A_i`` of the mesh
    scaled to area ``4 pi`` and ``L`` the cotangent Laplacian:

    1. ``H = M^{-1} L U`` (the Laplacian of the map; the energy's L2 gradient is ``-H``);
    2. ``G_i = H_i - (H_i . U_i) U_i`` (tangential part: the normal component is
       removed) and stop if ``sqrt(sum_i A_i |G_i|^2 / 4 pi) <= gtol``;
    3. ``U_i <- (U_i + step G_i) / |U_i + step G_i|`` (fixed step, projection
       back to the sphere);
    4. ``c = sum_i A_i U_i / sum_i A_i`` and ``U_i <- (U_i - c) / |U_i - c|``
       (Gu-Yau normalization, which excludes the collapse of the map to a point).

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int array
        Closed genus-0 mesh, outward oriented.
    U0 : (n, 3) float64 array
        Initial map (the paper's comparison starts from the Gauss map).
    step : float, optional
        Fixed step size; default :func:`stable_step`.
    gtol : float
        Stopping tolerance on the RMS Riemannian gradient (the library's rule).
    max_iter : int
        Iteration cap.
    max_seconds : float or None
        Wall-time cap; ``None`` for none.

    Returns
    -------
    GuYauResult
    """
    t0 = time.perf_counter()
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    L = igl.cotmatrix(V, F).tocsr()
    area = to_sphere_area(np.asarray(
        igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_BARYCENTRIC).diagonal(), dtype=np.float64))
    inv_area = 1.0 / area
    total = float(area.sum())
    if step is None:
        step = stable_step(L, area)
    U = np.asarray(U0, dtype=np.float64)
    U = U / np.linalg.norm(U, axis=1, keepdims=True)

    converged, message, k = False, f"reached max_iter={max_iter}", 0
    while True:
        LU = L @ U
        H = LU * inv_area[:, None]
        G = H - np.einsum("ij,ij->i", H, U)[:, None] * U
        gnorm = float(np.sqrt(area @ np.einsum("ij,ij->i", G, G) / total))
        if gnorm <= gtol:
            converged, message = True, f"RMS Riemannian gradient {gnorm:.3g} <= gtol={gtol:g}"
            break
        if k >= max_iter:
            break
        if max_seconds is not None and time.perf_counter() - t0 > max_seconds:
            message = (f"time cap {max_seconds:g} s reached after {k} iterations "
                       f"(RMS Riemannian gradient {gnorm:.3g} > gtol={gtol:g})")
            break
        U = U + step * G
        U /= np.linalg.norm(U, axis=1, keepdims=True)
        U = U - (area @ U) / total
        U /= np.linalg.norm(U, axis=1, keepdims=True)
        k += 1
    energy = float(-0.5 * np.sum(U * LU))
    return GuYauResult(U=U, converged=converged, message=message, nit=k, energy=energy,
                       grad_norm=gnorm, step=step, seconds=time.perf_counter() - t0)

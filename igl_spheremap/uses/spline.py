"""Smooth deformations of the sphere that carry landmark points exactly to given positions.

:func:`deform` interpolates the landmarks' displacements (tangent vectors of
the great circles to their new positions, length = angle in radians) by a
thin-plate spline of the chordal distance, ``phi(r) = r^2 log r`` with the
linear polynomials ``1, x, y, z`` (Duchon 1977; it is conditionally positive
definite of order 2 in R^3, so on the sphere too; for ``k <= 4`` landmarks
the constant alone first, see :data:`AFFINE_MIN_LANDMARKS`), and applies the
interpolated field through the exponential map.

A thin-plate spline interpolates with the least bending energy and has no
width to choose: a radial kernel of one global width is ill-conditioned for
close landmarks when wide and pinches the triangles in front of a landmark
carried beyond its width when narrow (``docs/decisions.md``).

Rounding: the conformal map crushes thin features (a landmark's one-ring can
span 1e-14).  Near each landmark (within
:data:`LINEAR_RADIUS` times its distance to the nearest other landmark) the
map is its target plus the deformation's differential applied to the offset
from the landmark, so that such triangles are moved as a whole, not by the
rounding noise of absolute positions; squared distances are taken from
coordinate differences (``2 - 2 x.a`` loses all digits below 1e-8); and the
spline's residual at the landmarks is spread over bumps that vanish at the
other landmarks instead of snapping the landmark row alone.
"""

import numpy as np

from ..mesh.arrays import rowdot, unit_rows
from ..sphere.geodesics import exp_map, log_map

#: Radius, as a fraction of a landmark's distance to the nearest other landmark,
#: within which the deformation is replaced by its linearization at the landmark
#: (blended back over the outer half).  Its relative error over a triangle
#: there is about the radius times the field's second derivative.
LINEAR_RADIUS = 1e-3

#: Fewest landmarks for which the spline's polynomial part includes ``x, y, z``
#: by default.  With ``k <= 4`` the linear polynomials alone interpolate the
#: ``k`` displacements, the kernel part is forced to 0 and the field is
#: affine: its tangent projection stretches the whole sphere instead of
#: bending it around the landmarks.  Neither is better on every pair with
#: ``k = 4``, so :func:`igl_spheremap.uses.landmarks.deformed` tries the
#: constant first and the affine field when it fails (``docs/decisions.md``).
AFFINE_MIN_LANDMARKS = 5


def nearest_spacing(A):
    """Chordal distance from each row of ``A`` to the nearest other row ((k,); 2 when alone)."""
    if A.shape[0] < 2:
        return np.full(A.shape[0], 2.0)
    from scipy.spatial import cKDTree

    return cKDTree(A).query(A, k=2)[0][:, 1]


def _sq_dist(X, A):
    """(n, k) squared distances between the rows of ``X`` and ``A``, from differences."""
    out = np.empty((X.shape[0], A.shape[0]))
    for j in range(A.shape[0]):
        D = X - A[j]
        out[:, j] = rowdot(D, D)
    return out


def _tps(r2):
    """Thin-plate kernel ``r^2 log r`` of the squared distance ``r2``."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(r2 > 0, 0.5 * r2 * np.log(np.where(r2 > 0, r2, 1.0)), 0.0)


def spline_field(A, D, linear=None):
    """The thin-plate spline on the sphere through the tangent vectors ``D`` at ``A``.

    The polynomial part is linear (``1, x, y, z``) or the constant alone;
    by default linear from :data:`AFFINE_MIN_LANDMARKS` landmarks on.

    Parameters
    ----------
    A : (k, 3) float64 array
        Distinct unit vectors.
    D : (k, 3) float64 array
        Values at ``A``.
    linear : bool, optional
        Whether the polynomial part includes ``x, y, z`` (default:
        ``k >= AFFINE_MIN_LANDMARKS``).

    Returns
    -------
    callable
        ``field(X, r2=None)``: (n, 3) -> (n, 3) values (not yet projected on
        tangent planes); ``field(A) == D`` up to rounding.  ``r2``: the (n, k)
        squared distances from ``X`` to ``A`` where the caller has them.
    """
    k = A.shape[0]
    linear = k >= AFFINE_MIN_LANDMARKS if linear is None else bool(linear)
    P = np.hstack([np.ones((k, 1)), A]) if linear else np.ones((k, 1))
    npoly = P.shape[1]
    M = np.block([[_tps(_sq_dist(A, A)), P], [P.T, np.zeros((npoly, npoly))]])
    # least squares: with one or two landmarks, or 5 or more on one circle, the
    # solution is not unique and the minimum-norm one is taken
    coef = np.linalg.lstsq(M, np.vstack([D, np.zeros((npoly, 3))]), rcond=None)[0]
    alpha, beta = coef[:k], coef[k:]

    def field(X, r2=None):
        Z = _tps(_sq_dist(X, A) if r2 is None else r2) @ alpha + beta[0]
        return Z + X @ beta[1:] if linear else Z
    return field


def deform(U, A, B, lm, chunk=1 << 15, linear=None):
    """``U`` deformed smoothly so that the landmark rows go from ``A`` to ``B`` (exactly).

    Parameters
    ----------
    U : (n, 3) float64 array
        Unit rows (a spherical map).
    A, B : (k, 3) float64 arrays
        The landmarks' rows of ``U`` and where they go (unit rows, ``A`` distinct).
    lm : (k,) int array
        The landmarks' row indices.
    chunk : int
        Rows per block (memory ``O(chunk k)``).
    linear : bool, optional
        Polynomial part of the spline (:func:`spline_field`).

    Returns
    -------
    (n, 3) float64 array
        Unit rows; ``Y[lm] == B``.  Far from the landmarks points move by the
        spline's smooth field; nothing guarantees the result is fold-free (the
        caller tests it).
    """
    D = log_map(A, B)
    field = spline_field(A, D, linear)
    spacing = nearest_spacing(A)
    res = D - field(A)
    rho2 = (spacing / 3.0) ** 2

    def mapped(X, r2=None):
        r2 = _sq_dist(X, A) if r2 is None else r2
        d = field(X, r2)
        d += np.maximum(1.0 - r2 / rho2, 0.0) ** 3 @ res
        return exp_map(X, d)

    near = LINEAR_RADIUS * spacing
    J = _differentials(mapped, A, 1e-3 * near)
    Y = np.empty_like(U)
    for a in range(0, U.shape[0], chunk):
        X = U[a:a + chunk]
        d2 = _sq_dist(X, A)
        Z = mapped(X, d2)
        r2 = d2 / near ** 2
        i = np.argmin(r2, axis=1)
        t = np.sqrt(r2[np.arange(X.shape[0]), i])
        sel = np.flatnonzero(t < 1.0)
        if sel.size:
            j = i[sel]
            lin = unit_rows(B[j] + np.einsum("nij,nj->ni", J[j], X[sel] - A[j]))
            w = np.clip(2.0 - 2.0 * t[sel], 0.0, 1.0)[:, None]
            Z[sel] = np.where(w == 1.0, lin, unit_rows(w * lin + (1.0 - w) * Z[sel]))
        Y[a:a + chunk] = Z
    Y[lm] = B
    return Y


def _differentials(mapped, A, h):
    """(k, 3, 3) central-difference Jacobians of ``mapped`` at the rows of ``A``.

    ``J[i] @ x`` is the derivative along a tangent vector ``x`` at ``A[i]``
    (step ``h[i]`` along the projections of the three axes).
    """
    J = np.zeros((A.shape[0], 3, 3))
    for e in np.eye(3):
        T = e - (A @ e)[:, None] * A
        diff = mapped(unit_rows(A + h[:, None] * T)) - mapped(unit_rows(A - h[:, None] * T))
        J += np.einsum("ni,j->nij", diff / (2.0 * h[:, None]), e)
    return J

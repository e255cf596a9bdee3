"""Per-vertex data of a spherical triangle mesh as a function on the sphere, with its gradient.

A fold-free spherical mesh ``(U, F)`` tiles the sphere by the cones of its
faces (:func:`igl_spheremap.sphere.locate.locate_on_sphere`).  Per-vertex
values ``f`` extend to every direction ``x`` by linear interpolation in the
face whose cone holds ``x``, with the barycentric coordinates of the central
(gnomonic) projection onto the chordal triangle.  For a face ``(i, j, k)`` with
``n_i = U_j x U_k``, ``n_j = U_k x U_i``, ``n_k = U_i x U_j`` and
``N = n_i + n_j + n_k`` these are ``b_c(x) = (x . n_c) / (x . N)``, so

    g(x) = (x . m) / (x . N),    m = f_i n_i + f_j n_j + f_k n_k,

a ratio of linear forms, homogeneous of degree 0 in ``x``.  Its gradient

    grad g(x) = (m (x . N) - N (x . m)) / (x . N)^2

is orthogonal to ``x`` (Euler's identity), so on the unit sphere it is the
Riemannian gradient itself.  ``g`` is continuous across edges and smooth in
each cone: the interpolation of :func:`igl_spheremap.resample` (the same
coordinates), made differentiable for the data term of
:class:`igl_spheremap.optimize.matching.FeatureMatchEnergy`.

Point location walks from the faces of the previous call (a registration moves
points a little between evaluations): :func:`igl_spheremap.sphere.locate.locate_from`,
the one walk of the package.
"""

import igl
import numpy as np

from ..errors import plural
from ..mesh.arrays import as_faces, as_points, cross_rows, unit_rows
from .folds import count_folds
from .locate import locate_from, locate_on_sphere

class SphereField:
    """Values on the vertices of a spherical mesh, interpolated on the sphere with their gradient.

    Parameters
    ----------
    U : (k, 3) float array
        A fold-free spherical mesh, faces oriented outward; any radius (rows
        are normalized).
    F : (t, 3) int array
        Its triangles.
    values : (k,) or (k, d) float array, optional
        Per-vertex values (``d`` fields, any units); see :meth:`set_values`.

    Attributes
    ----------
    U : (k, 3) float64 array
        Unit vectors.
    F : (t, 3) int64 array
    d : int
        Number of fields (0 before values are set).

    Raises
    ------
    ValueError
        ``U`` not (k, 3) finite numbers, ``F`` not (t, 3) integer indices into it, or
        faces of ``U`` folded (libigl's adjacency and the point location need a tiling).
    """

    def __init__(self, U, F, values=None):
        as_points(U, "U")  # checked, not converted: the layout sets BLAS's summation order
        self.U = unit_rows(U)
        self.F = as_faces(F, self.U.shape[0])
        folds = count_folds(self.F, self.U)
        if folds:
            raise ValueError(f"the sphere has {plural(folds, 'folded face')}; a field needs a "
                             "fold-free spherical mesh, faces oriented outward")
        Ui, Uj, Uk = (self.U[self.F[:, c]] for c in range(3))
        # n[:, c]: normal of the plane through the origin and the edge opposite corner c
        self.n = np.stack([cross_rows(Uj, Uk), cross_rows(Uk, Ui), cross_rows(Ui, Uj)], axis=1)
        self.N = self.n.sum(axis=1)
        self.TT = np.asarray(igl.triangle_triangle_adjacency(self.F)[0], dtype=np.int64)
        self.m = None
        self.d = 0
        if values is not None:
            self.set_values(values)

    def set_values(self, values):
        """Set the per-vertex values ((k,) or (k, d) float array, one row per vertex).

        Raises
        ------
        ValueError
            If ``values`` does not have one row per vertex.
        """
        f = np.asarray(values, dtype=np.float64)
        f = f[:, None] if f.ndim == 1 else f
        if f.ndim != 2 or f.shape[0] != self.U.shape[0]:
            raise ValueError(f"values must have {self.U.shape[0]} rows, got shape {np.shape(values)}")
        self.m = np.einsum("tcd,tcx->tdx", f[self.F], self.n)  # sum_c f[F[t, c], d] n[t, c]
        self.d = f.shape[1]

    def locate(self, P, face=None):
        """Face whose cone holds each direction of ``P`` ((q, 3) float64), walking from ``face``.

        Parameters
        ----------
        P : (q, 3) float64 array
            Directions (non-zero).
        face : (q,) int array, optional
            Starting faces (default: located from scratch).

        Returns
        -------
        (q,) int64 array
        """
        P = np.asarray(P, dtype=np.float64)
        if face is None:
            return locate_on_sphere(self.U, self.F, P)[0]
        return locate_from(self.U, self.F, unit_rows(P), face, self.TT)[0]

    def __call__(self, P, face=None, gradient=True):
        """Values (and gradients) of the fields at directions ``P``.

        Parameters
        ----------
        P : (q, 3) float64 array
            Directions; unit vectors for the gradient to be the Riemannian one.
        face : (q,) int array, optional
            Starting faces of the walk (e.g. the ``face`` of the previous call).
        gradient : bool
            Also return the gradients.

        Returns
        -------
        g : (q, d) float64 array
            Interpolated values.
        grad : (q, d, 3) float64 array
            ``dg/dP`` (orthogonal to ``P``), only with ``gradient``.
        face : (q,) int64 array
            Face of each point.

        Raises
        ------
        ValueError
            No values set.
        """
        if self.m is None:
            raise ValueError("no values set")
        face = self.locate(P, face)
        N, m = self.N[face], self.m[face]
        xN = np.einsum("qx,qx->q", P, N)
        xm = np.einsum("qx,qdx->qd", P, m)
        g = xm / xN[:, None]
        if not gradient:
            return g, face
        grad = (m * xN[:, None, None] - N[:, None, :] * xm[:, :, None]) / (xN * xN)[:, None, None]
        return g, grad, face

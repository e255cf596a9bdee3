"""Intrinsic descriptors of the vertices relative to the landmarks, and the penalty on them.

Landmark ``l1[j]`` of surface 1 and ``l2[j]`` of surface 2 are a pair, so a good map
from surface 1 onto surface 2 keeps each vertex's descriptor relative to the
landmarks.  The descriptor is the harmonic landmark coordinates: column ``j`` harmonic
away from the landmarks, 1 on a small disk at landmark ``j`` and 0 on the others
(:func:`landmark_harmonics`, :func:`disk_radius`).  Dirichlet energy is invariant under
conformal maps, so they follow a map close to conformal, not only an isometry.
Geodesic distances to the landmarks were measured too and do worse on pairs that are
not isometric (they differ by 10-15% of their values between the two surfaces of the
true correspondence; docs/decisions.md).

:class:`DescriptorTerm` is the penalty ``w sum_i A_i |d1(i) - d2(X_i)|^2 / k`` of the
distortion stage (:mod:`igl_spheremap.uses.surface_arap`), with ``d2`` linear in each
face of surface 2 (the vertex values interpolated), hence its gradient constant per
face, and its Gauss-Newton model (the residuals linear in ``X`` inside a face).
Distances and harmonic functions of landmarks as descriptors of maps between shapes:
Ovsjanikov, Ben-Chen, Solomon, Butscher, Guibas, "Functional maps", TOG 2012, section 6.
"""
import copy

import igl
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.sparse import csgraph

from ..mesh.operators import laplacian

#: Radius of the landmarks' disks of :func:`landmark_harmonics`, over ``sqrt(area)``.
DISK_RADIUS = 0.05

#: Smallest radius of the landmarks' disks, in mean edge lengths of the coarser surface.
DISK_EDGES = 1.5


def landmark_harmonics(V, F, landmarks, radius=0.0):
    """Harmonic landmark coordinates (n, k) float64: column ``j`` harmonic away from the
    landmarks' disks, 1 on the disk of ``landmarks[j]`` and 0 on the others.

    Dirichlet energy is invariant under conformal maps, so these functions follow a
    map that is close to conformal (the discrete version: the intrinsic Delaunay
    cotangent Laplacian, :func:`igl_spheremap.mesh.operators.laplacian`).  The disk of
    a landmark is the vertices within ``radius`` of it along the edges (each vertex
    in the disk of its nearest landmark): a point's capacity is zero, so with single
    vertices the functions depend on the resolution (they flatten as it grows);
    disks of one radius on both surfaces make them comparable.  The columns sum to
    1 (a partition of unity); dimensionless.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int64 array
    landmarks : (k,) int64 array
        Distinct vertex indices.
    radius : float
        Of the disks, in the units of ``V`` (0: the landmark vertices alone).

    Returns
    -------
    (n, k) float64 array
    """
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    lm = np.asarray(landmarks, dtype=np.int64)
    n = V.shape[0]
    E = igl.edges(F)
    W = sp.coo_matrix((np.linalg.norm(V[E[:, 0]] - V[E[:, 1]], axis=1), (E[:, 0], E[:, 1])),
                      shape=(n, n))
    D = csgraph.dijkstra(W.tocsr(), directed=False, indices=lm, limit=radius)  # (k, n)
    owner = np.argmin(D, axis=0)
    disk = np.isfinite(D.min(axis=0)) & (D.min(axis=0) <= radius)
    disk[lm] = True
    owner[lm] = np.arange(lm.size)
    L = -laplacian(V, F)
    out = np.zeros((n, lm.size))
    fixed = np.flatnonzero(disk)
    out[fixed, owner[fixed]] = 1.0
    free = np.flatnonzero(~disk)
    out[free] = spla.splu(L[free][:, free].tocsc()).solve(-(L[free][:, fixed] @ out[fixed]))
    return out


def disk_radius(V1, F1, V2, F2):
    """The disk radius of :func:`landmark_harmonics` for two surfaces at one scale (float):
    :data:`DISK_RADIUS` of ``sqrt(area)`` (surface 2's), and at least :data:`DISK_EDGES`
    mean edge lengths of the coarser surface, so that every disk holds a few vertices."""
    def mean_edge(V, F):
        E = igl.edges(np.asarray(F, dtype=np.int64))
        return float(np.linalg.norm(V[E[:, 0]] - V[E[:, 1]], axis=1).mean())
    area = igl.doublearea(np.asarray(V2, dtype=np.float64), np.asarray(F2, dtype=np.int64)).sum() / 2
    return max(DISK_RADIUS * np.sqrt(area), DISK_EDGES * max(mean_edge(V1, F1), mean_edge(V2, F2)))


class DescriptorTerm:
    """``w sum_i A_i |d1(i) - d2(X_i)|^2 / k``: surface 1's descriptors against surface 2's at the images.

    Parameters
    ----------
    d1 : (n1, k) float64 array
        Descriptors of surface 1's vertices (:func:`landmark_harmonics`).
    d2 : (n2, k) float64 array
        Descriptors of surface 2's vertices, the same landmarks in the same order.
    V2, F2 : arrays
        Surface 2 ((n2, 3) float64, at the scale of the images ``X``; (m2, 3) int64).
    area : (n1,) float64 array
        Vertex areas ``A_i`` of surface 1 (at the scale of the distortion energy).
    weight : float
        ``w``.

    Notes
    -----
    In face ``f`` of surface 2 with corner ``a``, ``d2(X) = d2(V_a) + G_f (X - V_a)``
    with the (k, 3) gradient ``G_f`` of the linear interpolant; for points off the
    face's plane this is the value at their projection onto the plane.
    """

    def __init__(self, d1, d2, V2, F2, area, weight):
        self.d1 = np.asarray(d1, dtype=np.float64)
        self.F2 = np.asarray(F2, dtype=np.int64)
        self.V2 = np.asarray(V2, dtype=np.float64)
        k = self.d1.shape[1]
        m2 = self.F2.shape[0]
        grad = igl.grad(self.V2, self.F2)  # rows: x of every face, then y, then z
        self.gradients = np.transpose(np.asarray(grad @ d2).reshape(3, m2, k), (1, 2, 0))
        self.corner = np.asarray(d2, dtype=np.float64)[self.F2[:, 0]]  # (m2, k)
        self.weight = weight
        self.scale = weight * np.asarray(area, dtype=np.float64) / max(k, 1)  # w A_i / k

    def restricted(self, rows, area):
        """The term of the vertices ``rows`` (c,) of surface 1 alone, with vertex areas ``area``
        (c,) (e.g. a coarse version of surface 1 on these vertices)."""
        out = copy.copy(self)
        out.d1 = self.d1[rows]
        out.scale = self.weight * np.asarray(area, dtype=np.float64) / max(self.d1.shape[1], 1)
        return out

    def weighted(self, fraction):
        """The same term at ``fraction`` (float, > 0) of its weight ``w``."""
        out = copy.copy(self)
        out.weight = self.weight * fraction
        out.scale = self.scale * fraction
        return out

    def isotropic_stiffness(self, face, idx):
        """``c_i |G_i|^2 / 2`` (q,) float64: the Gauss-Newton blocks of the vertices ``idx`` (q,)
        with images in the faces ``face`` (q,) of surface 2, as multiples of the identity (the
        mean of their eigenvalues in the plane), for a preconditioner."""
        G = self.gradients[face]
        return 0.5 * self.scale[idx] * np.sum(G * G, axis=(1, 2))

    def residuals(self, face, X, idx=slice(None)):
        """``r_i = d2(X_i) - d1(i)`` (q, k) and the gradients ``G_i`` (q, k, 3) of ``d2`` there.

        Parameters
        ----------
        face : (q,) int64 array
            Faces of surface 2 containing the images.
        X : (q, 3) float64 array
            The images, on surface 2.
        idx : (q,) int64 array or slice
            Which vertices of surface 1 the rows are (all by default).
        """
        G = self.gradients[face]
        r = self.corner[face] + np.einsum("ikl,il->ik", G, X - self.V2[self.F2[face, 0]])
        return r - self.d1[idx], G

    def value(self, face, X):
        """The penalty (float) at the images ``X`` (n1, 3) in the faces ``face`` (n1,)."""
        r, _ = self.residuals(face, X)
        return float(self.scale @ np.sum(r * r, axis=1))

    def gauss_newton(self, face, X, idx, T):
        """The penalty's Gauss-Newton model for steps ``T_i delta_i`` of the vertices ``idx``.

        ``E(X + T delta) ~ E(X) + 2 sum_i delta_i^T g_i + sum_i delta_i^T H_i delta_i``
        (exact while each image stays in its face).

        Parameters
        ----------
        face : (n1,) int64 array
            Faces of surface 2 containing the images.
        X : (n1, 3) float64 array
            The images.
        idx : (q,) int64 array
            The vertices that move.
        T : (q, 3, 2) float64 array
            Orthonormal bases of the planes of surface 2's faces ``face[idx]``.

        Returns
        -------
        H : (q, 2, 2) float64 array
            ``c_i (G_i T_i)^T (G_i T_i)`` with ``c_i = w A_i / k``.
        g : (q, 2) float64 array
            ``c_i (G_i T_i)^T r_i``: half the penalty's gradient in the planes.
        """
        r, G = self.residuals(face[idx], X[idx], idx)
        GT = G @ T  # (q, k, 2)
        c = self.scale[idx]
        H = c[:, None, None] * np.einsum("ika,ikb->iab", GT, GT)
        g = c[:, None] * np.einsum("ika,ik->ia", GT, r)
        return H, g

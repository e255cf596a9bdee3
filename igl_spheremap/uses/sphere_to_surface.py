"""``phi2^-1``: from the sphere to a surface through the surface's fold-free spherical map.

Surface 2 has a fixed fold-free spherical map ``phi2`` (``U2`` on ``F2``).  A
direction ``u`` lands on surface 2 at ``phi2^-1(u)``: the face of ``U2`` whose
cone contains ``u`` (central projection, as
:func:`igl_spheremap.sphere.locate.locate_on_sphere`) and the barycentric
coordinates there, applied to surface 2's vertices.  Point location walks
from the faces of the previous call (:func:`igl_spheremap.sphere.locate.locate_from`),
for optimizers that evaluate nearby maps many times.
"""

import igl
import numpy as np

from ..mesh.arrays import cross_rows, moved_unit_rows
from ..mesh.frames import tangent_bases
from ..sphere.locate import chordal_tree, locate_from, locate_on_sphere

#: Regularization of the 3 x 3 solve of :meth:`SphereToSurface.walk`, relative to its trace:
#: a degenerate face of surface 2 makes the Jacobian of rank < 2.
WALK_RIDGE = 1e-12

#: :meth:`SphereToSurface.walk` keeps a point where it was when the walk carried its image more
#: than this many times as far as its displacement: its linear substeps crossed faces of
#: ``phi2`` too small for them (crowding near float64's resolution).
WALK_OVERSHOOT = 100.0


class SphereToSurface:
    """``phi2^-1``: directions of the sphere to points of surface 2, with its Jacobian.

    Parameters
    ----------
    U2 : (n2, 3) float64 array
        Fold-free spherical map of surface 2 (unit rows).
    F2 : (m2, 3) int64 array
        Its faces, oriented outward.
    V2 : (n2, 3) float64 array
        Surface 2's vertices (any scale).

    Notes
    -----
    For a face with sphere vertices ``S_0, S_1, S_2`` the gnomonic barycentric
    coordinates of a direction ``u`` are ``b_j = w_j / sum(w)`` with the signed
    volumes ``w_j = u . n_j``, ``n_j = S_{j+1} x S_{j+2}``; hence
    ``db_j/du = (n_j sum(w) - w_j N) / sum(w)^2`` with ``N = sum_j n_j``, and
    ``dX/du = sum_j V_j db_j/du`` (rank 2: ``X`` does not change along ``u``).
    """

    def __init__(self, U2, F2, V2):
        self.U2 = np.ascontiguousarray(U2, dtype=np.float64)
        self.F2 = np.ascontiguousarray(F2, dtype=np.int64)
        self.V2 = np.ascontiguousarray(V2, dtype=np.float64)
        S = self.U2[self.F2]
        c = S.mean(axis=1)
        d = S - c[:, None, :]
        # n_j = S_{j+1} x S_{j+2} = c x (d_{j+2} - d_{j+1}) + d_{j+1} x d_{j+2}: small terms
        # first, so that the normals of tiny (crowded) faces keep their relative accuracy
        self.normals = np.stack(
            [cross_rows(c, d[:, (j + 2) % 3] - d[:, (j + 1) % 3])
             + cross_rows(d[:, (j + 1) % 3], d[:, (j + 2) % 3]) for j in range(3)], axis=1)
        self.TT = np.ascontiguousarray(igl.triangle_triangle_adjacency(self.F2)[0],
                                       dtype=np.int64)
        self.tree = chordal_tree(self.U2, self.F2)
        self.Vf = self.V2[self.F2]
        n = cross_rows(self.Vf[:, 1] - self.Vf[:, 0], self.Vf[:, 2] - self.Vf[:, 0])
        self.face_normals = n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
        self.vertex_normals = igl.per_vertex_normals(
            self.V2, self.F2, igl.PER_VERTEX_NORMALS_WEIGHTING_TYPE_AREA)

    def start(self, U):
        """Faces (n,) of the directions ``U`` (n, 3) located from scratch (AABB tree and walk)."""
        return locate_on_sphere(self.U2, self.F2, U)[0]

    def locate(self, U, face):
        """Faces (n,) whose cones contain the directions ``U`` (n, 3) and the signed volumes
        (n, 3), walking from ``face`` (n,)."""
        return locate_from(self.U2, self.F2, U, face, self.TT, self.tree)

    def points(self, face, w):
        """``X = phi2^-1(U)`` (n, 3) from :meth:`locate`'s output."""
        return np.einsum("ij,ijk->ik", self.barycentric(w), self.Vf[face])

    def surface_normals(self, face, w):
        """Unit normals (n, 3) of surface 2 at the images: its area-weighted vertex normals
        (``igl.per_vertex_normals``) interpolated in the located faces.  Continuous in the
        image, so an image on an edge or a vertex of surface 2 gets the same normal
        whichever of its faces it was located in."""
        N = np.einsum("ij,ijk->ik", self.barycentric(w), self.vertex_normals[self.F2[face]])
        return N / np.maximum(np.linalg.norm(N, axis=1, keepdims=True), 1e-300)

    @staticmethod
    def barycentric(w):
        """Barycentric coordinates (n, 3): the volumes clipped at 0 and normalized."""
        b = np.maximum(w, 0.0)
        return b / b.sum(axis=1, keepdims=True)

    def jacobian(self, face, w):
        """``dX/dU`` (n, 3, 3) inside the located faces (rank 2; see the class notes)."""
        sig = w.sum(axis=1)
        n = self.normals[face]
        N = n.sum(axis=1)
        db = (n * sig[:, None, None] - w[:, :, None] * N[:, None, :]) / sig[:, None, None] ** 2
        return np.einsum("ijk,ijl->ikl", self.Vf[face], db)

    def walk(self, U, face, d, substeps=4):
        """Move the images ``X = phi2^-1(U)`` along surface 2 by the displacements ``d`` (n, 3).

        ``substeps`` steps of ``d / substeps``, each projected onto the current
        face's plane and carried to the sphere by the least-squares inverse of
        :meth:`jacobian` (tangent to the sphere), so that the points follow the
        surface and never jump across a thin part as a closest-point projection can.
        Where ``phi2`` is crowded, a direction's move of 1e-9 can cross many faces whose
        Jacobians differ by orders of magnitude, and a linear substep then lands the image
        far from where it was sent: a point whose image ends more than
        :data:`WALK_OVERSHOOT` times as far from its start as ``|d|`` stays where it was.

        Returns
        -------
        U : (n, 3) float64 array
            The new directions (unit rows).
        face : (n,) int64 array
            Their faces.
        """
        face, w = self.locate(U, face)
        U0, face0, X0 = U, face, self.points(face, w)
        limit = WALK_OVERSHOOT * np.linalg.norm(d, axis=1)
        d = d / substeps
        for _ in range(substeps):
            J = self.jacobian(face, w)
            nrm = self.face_normals[face]
            dt = d - np.einsum("ij,ij->i", d, nrm)[:, None] * nrm
            A = np.einsum("ikl,ikm->ilm", J, J) + U[:, :, None] * U[:, None, :]
            A += (WALK_RIDGE * np.trace(A, axis1=1, axis2=2))[:, None, None] * np.eye(3)
            delta = np.linalg.solve(A, np.einsum("ikl,ik->il", J, dt)[:, :, None])[:, :, 0]
            U = moved_unit_rows(U, U + delta)
            face, w = self.locate(U, face)
        lost = np.linalg.norm(self.points(face, w) - X0, axis=1) > limit
        return np.where(lost[:, None], U0, U), np.where(lost, face0, face)

    def tangent_bases(self, face):
        """Orthonormal bases (n, 3, 2) of the planes of surface 2's faces ``face``."""
        return tangent_bases(self.face_normals[face])

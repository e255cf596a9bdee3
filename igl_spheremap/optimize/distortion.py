"""Distortion energies of a spherical map measured per face by the Jacobian of the map.

For a map ``U`` of a surface ``(V, F)`` onto the sphere, the affine map from a
face of the surface (scaled to total area ``4 pi``) onto the chordal triangle
of its image has a Jacobian ``J_f`` (3 x 2 in the face's own orthonormal
frame).  An energy ``E(U) = sum_f A_f e(J_f)`` of the singular values of
``J_f`` measures the map's distortion: :class:`JacobianEnergy` computes the
Jacobians and carries ``de/dJ`` back to the vertices, and a subclass gives
``e`` and ``de/dJ`` (:meth:`JacobianEnergy.face_energy`).  Here:

* :class:`SymmetricDirichletEnergy`: ``e = (|J|_F^2 + |J^+|_F^2) / 2``, area and
  angle distortion together (the area-balanced sphere,
  :func:`igl_spheremap.optimize.area_balanced.area_balanced_map`).

The conformal (MIPS-type) energy of the guaranteed path is not one of them: its
denominator is the fold test's signed volume, not the chordal Jacobian's determinant
(:class:`igl_spheremap.optimize.conformal_distortion.ConformalDistortionEnergy`).
"""

import igl
import numpy as np
import scipy.sparse as sp

from ..mesh.operators import laplacian
from .direction import H1Metric, make_metric
from .energy import Energy, Evaluation


#: Upper clip of the face weights of :meth:`JacobianEnergy.stiffness` (the lowest is about 1):
#: a wider spread makes the H1 metric too ill-conditioned to factorize in float64 (a crushed
#: face of a conformal map can have ``1 / det C`` above 1e20; ``docs/decisions.md``).
MAX_STIFFNESS = 1e8


class JacobianEnergy(Energy):
    """``E(U) = sum_f A_f e(J_f)``: the base of the per-face Jacobian distortion energies.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int64 array
        The surface (a validated mesh, faces outward).
    metric : {"H1", "L2"}
        Search direction metric; H1 uses the surface's intrinsic Delaunay
        cotangent Laplacian (:func:`igl_spheremap.mesh.operators.laplacian`).
    h1_solver : str
        As :func:`igl_spheremap.optimize.direction.make_metric`.

    Attributes
    ----------
    face_area : (m,) float64 array
        ``A_f``, the surface scaled to total area ``4 pi``.
    """

    def __init__(self, V, F, metric="H1", h1_solver="auto"):
        V = np.asarray(V, dtype=np.float64)
        F = np.asarray(F, dtype=np.int64)
        A = igl.doublearea(V, F) / 2.0
        scale = np.sqrt(4.0 * np.pi / A.sum())
        Vs = V * scale
        self.F, self.n = F, V.shape[0]
        self.face_area = A * scale ** 2
        # the face's frame: e1 along its first edge; Dm = [[l1, x2], [0, y2]]
        d1, d2 = Vs[F[:, 1]] - Vs[F[:, 0]], Vs[F[:, 2]] - Vs[F[:, 0]]
        l1 = np.linalg.norm(d1, axis=1)
        x2 = np.einsum("ij,ij->i", d1, d2) / l1
        y2 = 2.0 * self.face_area / l1
        self.Dinv = np.zeros((F.shape[0], 2, 2))
        self.Dinv[:, 0, 0] = 1.0 / l1
        self.Dinv[:, 0, 1] = -x2 / (l1 * y2)
        self.Dinv[:, 1, 1] = 1.0 / y2
        area = np.bincount(F.ravel(), weights=np.repeat(self.face_area / 3.0, 3), minlength=self.n)
        super().__init__(area, make_metric(metric, laplacian(Vs, F), area, h1_solver))

    def jacobians(self, U):
        """``J_f`` of every face ((m, 3, 2) float64) for the map ``U`` (n, 3)."""
        F = self.F
        Ds = np.stack([U[F[:, 1]] - U[F[:, 0]], U[F[:, 2]] - U[F[:, 0]]], axis=2)
        return Ds @ self.Dinv

    def face_energy(self, J):
        """``(e, de/dJ)`` per face: (m,) and (m, 3, 2) float64; ``e = inf`` where undefined."""
        raise NotImplementedError

    def face_stiffness(self, J):
        """``w_f`` (m,): the weight of ``|J_f|_F^2 / 2`` in a quadratic model of ``e`` at ``J``.

        The base class's 1 makes :meth:`stiffness` the cotangent Laplacian.
        """
        return np.ones(J.shape[0])

    def stiffness(self, U):
        """``L_w = -sum_f A_f w_f S_f`` ((n, n) sparse, negative semidefinite) at the map ``U``.

        ``S_f = B_f B_f^T`` with ``B_f`` the gradients of the face's barycentric
        coordinates, so ``A_f |J_f|_F^2 = A_f tr(U_f^T S_f U_f)``: ``-L_w`` is the
        Hessian of ``sum_f A_f w_f |J_f|_F^2 / 2`` (each ``S_f`` is positive
        semidefinite, so ``L_w`` is whatever the angles), ``w_f`` from
        :meth:`face_stiffness` clipped at :data:`MAX_STIFFNESS`.
        """
        B = np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]]) @ self.Dinv
        w = self.face_area * np.minimum(self.face_stiffness(self.jacobians(U)), MAX_STIFFNESS)
        S = -(w[:, None, None] * (B @ np.transpose(B, (0, 2, 1))))
        rows = np.repeat(self.F, 3, axis=1).ravel()
        cols = np.tile(self.F, (1, 3)).ravel()
        return sp.csr_matrix((S.ravel(), (rows, cols)), shape=(self.n, self.n))

    def reweight(self, U):
        """Give the H1 metric the stiffness of the energy at ``U`` (:meth:`stiffness`), so that
        its direction is scaled face by face as the energy is (nothing with the L2 metric)."""
        if isinstance(self.metric, H1Metric):
            self.metric.set_stiffness(self.stiffness(U))

    def evaluate(self, U):
        e, dJ = self.face_energy(self.jacobians(U))
        value = float(self.face_area @ e) if np.all(np.isfinite(e)) else np.inf
        return Evaluation(U=U, value=value, cache=dJ)

    def euclidean_gradient(self, ev):
        dDs = (self.face_area[:, None, None] * ev.cache) @ np.transpose(self.Dinv, (0, 2, 1))
        G = np.zeros((self.n, 3))
        F = self.F
        for c in range(3):
            G[:, c] = (np.bincount(F[:, 1], weights=dDs[:, c, 0], minlength=self.n)
                       + np.bincount(F[:, 2], weights=dDs[:, c, 1], minlength=self.n)
                       - np.bincount(F[:, 0], weights=dDs[:, c, 0] + dDs[:, c, 1],
                                     minlength=self.n))
        return G


class SymmetricDirichletEnergy(JacobianEnergy):
    """``E(U) = 1/2 sum_f A_f (|J_f|_F^2 + |J_f^+|_F^2)``: isometric distortion of a spherical map.

    With singular values ``s1, s2`` of ``J_f``, ``|J|_F^2 + |J^+|_F^2 =
    s1^2 + s2^2 + s1^-2 + s2^-2 >= 4``, with equality only for an isometry, so
    the energy penalizes area and angle distortion together (Smith, Schaefer,
    "Bijective parameterization with free boundaries", SIGGRAPH 2015;
    Rabinovich, Poranne, Panozzo, Sorkine-Hornung, "Scalable locally injective
    mappings", ACM TOG 36(2) 2017).  It grows without bound as a face
    degenerates and is invariant under rotations of ``U`` (not under Möbius
    transformations).  A map onto the sphere cannot be an isometry, so the
    minimizer spreads the distortion: a sphere with low area and edge-length
    distortion, the role of FreeSurfer's ``mris_sphere`` (Fischl, Sereno, Dale,
    "Cortical surface-based analysis II", NeuroImage 9 1999).

    With ``C = J^T J``, ``|J|_F^2 = tr C`` and ``|J^+|_F^2 = tr C / det C``, so
    ``e = tr C (1 + 1 / det C) / 2`` and
    ``de/dJ = J (1 + 1 / det C) - (tr C / det C) J C^{-1}``.

    Parameters
    ----------
    V, F, metric, h1_solver
        As :class:`JacobianEnergy`.
    """

    def face_energy(self, J):
        C = np.einsum("mki,mkj->mij", J, J)
        trC = C[:, 0, 0] + C[:, 1, 1]
        detC = C[:, 0, 0] * C[:, 1, 1] - C[:, 0, 1] * C[:, 1, 0]
        if not np.all(detC > 0):
            return np.full(J.shape[0], np.inf), np.zeros_like(J)
        e = 0.5 * trC * (1.0 + 1.0 / detC)
        Cinv = np.empty_like(C)
        Cinv[:, 0, 0], Cinv[:, 1, 1] = C[:, 1, 1], C[:, 0, 0]
        Cinv[:, 0, 1], Cinv[:, 1, 0] = -C[:, 0, 1], -C[:, 1, 0]
        Cinv /= detC[:, None, None]
        dJ = J * (1.0 + 1.0 / detC)[:, None, None] - (trC / detC)[:, None, None] * (J @ Cinv)
        return e, dJ

    def face_stiffness(self, J):
        """``1 + 1 / det C``: ``e = w |J|_F^2 / 2`` with this weight held fixed (its
        Hessian along a uniform scaling of the face, ``1 + 3 / det C``, has the same order)."""
        C = np.einsum("mki,mkj->mij", J, J)
        return 1.0 + 1.0 / (C[:, 0, 0] * C[:, 1, 1] - C[:, 0, 1] * C[:, 1, 0])

"""Matching energies of a deformation of a sphere: a data term plus the membrane energy on a reference sphere.

Both energies here move a map ``U`` (n, 3) of a subject's vertices on the
sphere and regularize it by the Dirichlet (membrane) energy
``-1/2 tr(U^T L0 U)`` on the subject's reference sphere ``S0`` (``L0`` its
cotangent Laplacian): ``U = S0``, and any Möbius transformation of it,
minimizes it, and a deformation of ``S0`` pays for its departure from
conformality (shear), the harmonic energy of paper Eq. 6 with the reference
sphere as domain.  The search direction's metric is the Sobolev metric
``M - sigma^2 L0`` (``sigma`` a length on the unit sphere, radians): a
smoothed velocity, the "fluid" prior of Demons registration, while the
membrane weight is the "elastic" prior (Yeo et al., IEEE TMI 29(3) 2010,
Section II).

* :class:`FeatureMatchEnergy`: squared differences of per-vertex features
  against a target's, interpolated at the moving points (atlas registration,
  :func:`igl_spheremap.uses.atlas.register_sphere`);
* :class:`PointMatchEnergy`: squared distances to given points (following a
  map that may fold, under the fold barrier).
"""

import numpy as np

from ..errors import plural
from .direction import make_metric
from .energy import Energy, Evaluation


class FeatureMatchEnergy(Energy):
    """``E(U) = lambda/2 sum_i a_i sum_f w_f (s_if - g_f(U_i))^2 - mu/2 tr(U^T L0 U)``.

    The data term compares the subject's features ``s`` (n, d) with the
    target's ``g`` (:class:`igl_spheremap.sphere.field.SphereField`, piecewise
    linear on the target sphere, evaluated at the moving points ``U_i``),
    weighted by the vertex areas ``a_i`` (sum ``4 pi``), per-feature weights
    ``w_f`` and optional per-vertex weights: the sum of squared differences of
    Spherical Demons (Yeo et al., IEEE TMI 29(3) 2010, Eq. 3) and of
    FreeSurfer's ``mris_register`` (Fischl, Sereno, Tootell, Dale, HBM 8 1999).
    Gradient::

        dE/dU_i = -lambda a_i sum_f w_f (s_if - g_f(U_i)) grad g_f(U_i) - mu (L0 U)_i

    Parameters
    ----------
    field : igl_spheremap.sphere.field.SphereField
        The target's features (``d`` fields) on the target sphere.
    features : (n,) or (n, d) float array
        The subject's features, in the units of the target's (standardized).
    area : (n,) float64 array
        Vertex areas of the subject, summing to ``4 pi``: the data weights and
        the lumped mass of Algorithm 1.
    L0 : (n, n) sparse matrix
        Negative semidefinite Laplacian of the reference sphere.
    data_weight : float
        ``lambda`` (> 0).
    reg_weight : float
        ``mu`` (>= 0).
    sigma : float
        Smoothing length of the metric, radians (> 0).
    feature_weights : (d,) float array, optional
        ``w_f`` (default 1).
    vertex_weights : (n,) float array, optional
        Per-vertex data weights in [0, 1] (e.g. 0 on the medial wall); default 1.
    h1_solver : str
        How the metric is inverted (:func:`igl_spheremap.optimize.preconditioner.h1_preconditioner`).

    Raises
    ------
    ValueError
        The subject and the target have different numbers of features.
    """

    def __init__(self, field, features, area, L0, data_weight, reg_weight, sigma,
                 feature_weights=None, vertex_weights=None, h1_solver="auto"):
        s = np.asarray(features, dtype=np.float64)
        self.s = s[:, None] if s.ndim == 1 else s
        if self.s.shape[1] != field.d:
            raise ValueError(f"{plural(self.s.shape[1], 'subject feature')} but "
                             f"{plural(field.d, 'target field')}")
        super().__init__(area, make_metric("H1", (sigma * sigma) * L0, area, h1_solver))
        self.field, self.L0 = field, L0
        self.lam, self.mu = float(data_weight), float(reg_weight)
        w = np.ones(field.d) if feature_weights is None else np.asarray(feature_weights, float)
        a = self.area if vertex_weights is None else self.area * np.asarray(vertex_weights, float)
        self.wa = a[:, None] * w[None, :]  # (n, d) weights of the squared differences
        self.face = None

    def evaluate(self, U):
        g, grad, self.face = self.field(U, self.face)
        r = self.s - g
        data = 0.5 * float(np.sum(self.wa * r * r))
        L0U = self.L0 @ U
        reg = -0.5 * float(np.vdot(U, L0U))
        return Evaluation(U=U, value=self.lam * data + self.mu * reg,
                          cache=(r, grad, L0U, data, reg))

    def euclidean_gradient(self, ev):
        r, grad, L0U, _, _ = ev.cache
        G = -self.lam * np.einsum("qd,qdx->qx", self.wa * r, grad)
        if self.mu:
            G -= self.mu * L0U
        return G

    def terms(self, ev):
        """``(data, membrane)`` of an evaluation, without the weights."""
        return ev.cache[3], ev.cache[4]


class PointMatchEnergy(Energy):
    """``E(U) = lambda/2 sum_i a_i |U_i - Q_i|^2 - 1/2 tr(U^T L0 U)``: toward ``Q``, smoothly.

    Parameters
    ----------
    Q : (n, 3) float64 array
        The points to move toward (unit vectors; may fold).
    area : (n,) float64 array
        Vertex areas summing to ``4 pi``.
    L0 : (n, n) sparse matrix
        Negative semidefinite Laplacian of the reference sphere.
    weight : float
        ``lambda`` (> 0).
    sigma : float
        Smoothing length of the H1 metric, radians.
    """

    def __init__(self, Q, area, L0, weight, sigma):
        super().__init__(area, make_metric("H1", sigma * sigma * L0, area))
        self.Q, self.L0, self.lam = Q, L0, float(weight)

    def evaluate(self, U):
        D = U - self.Q
        L0U = self.L0 @ U
        value = (0.5 * self.lam * float(np.vdot(D * self.area[:, None], D))
                 - 0.5 * float(np.vdot(U, L0U)))
        return Evaluation(U=U, value=value, cache=(D, L0U))

    def euclidean_gradient(self, ev):
        D, L0U = ev.cache
        return self.lam * D * self.area[:, None] - L0U

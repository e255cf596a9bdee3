"""The map from surface 1 onto surface 2 made as rigid as possible, while it stays bijective.

The unknown is surface 1's fold-free spherical map ``U1``; its vertices land on
surface 2 at ``X = phi2^-1(U1)`` (:class:`igl_spheremap.uses.sphere_to_surface.SphereToSurface`),
and each triangle of surface 1 is mapped linearly onto the triangle of its
three images, with the 3 x 2 Jacobian ``J`` in the triangle's own frame.  The
energy is the as-rigid-as-possible distortion ``sum_t A_t |J_t - R_t|^2`` over
the triangles' areas ``A_t`` (both surfaces scaled to area ``4 pi``), ``R_t`` the
closest rotation into the image's plane (Sorkine, Alexa, "As-rigid-as-possible
surface modeling", SGP 2007; Liu, Zhang, Xu, Gotsman, Gortler, "A local/global
approach to mesh parameterization", SGP 2008), plus landmark springs and, optionally,
a penalty on the images' descriptors relative to the landmarks
(:class:`igl_spheremap.uses.descriptors.DescriptorTerm`, Gauss-Newton).  With ``robust``
the distortion is charged through the pseudo-Huber penalty :func:`robust_penalty`
instead, ``sum_t A_t psi(|J_t - R_t|^2)``, and each global step weighs the faces by the
penalty's slope at the current map.

Each iteration of :func:`refine`:

1. *local step*: ``R_t = J_t (J_t^T J_t)^(-1/2)`` in closed form, or, for an
   image turned over against surface 2's normal (its vertex normals interpolated at
   the images, so that the test does not depend on which face an image on a vertex
   of surface 2 was located in), the closest rotation in the
   tangent plane: the spherical maps are fold-free, yet chordal image triangles
   over curved or crowded parts of surface 2 can face the other way (several
   hundred on the cat pairs), and the reflection would keep them so at no cost;
2. *global step*: the minimizer of the energy with the rotations held, plus a
   small proximal term, restricted to the tangent planes of surface 2 at the
   images (2 unknowns per free vertex): a free 3-D step leaves the surface by
   several triangle heights, and projecting it back folds thin triangles.  The
   matrix changes only through the tangent planes: conjugate gradients solve it,
   preconditioned by the 3-D solve restricted to the planes (the 3-D matrix is
   factorized once; with a descriptor term, whose Gauss-Newton blocks are stiff
   near the landmarks, at the first step with the term's blocks at the images of
   that step as multiples of the identity added);
3. *retraction*: the images walked along surface 2 by the step
   (:meth:`SphereToSurface.walk`), then pulled back per vertex toward the
   previous map until no spherical triangle of surface 1 folds
   (:func:`igl_spheremap.sphere.folds.fold_free_blend`); the step is accepted
   when it lowers the energy, else shortened.

The map stays fold-free on the sphere, so the correspondence stays a bijection
(Schmidt, Born, Campen, Kobbelt, "Distortion-minimizing injective maps between
surfaces", TOG 2019, keep a map between surfaces bijective the same way: through
a fold-free map of a common domain).
"""

import igl
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..mesh.arrays import cross_rows, moved_unit_rows
from ..mesh.frames import tangent_bases, triangle_frames
from ..mesh.operators import SPHERE_AREA
from ..optimize.preconditioner import factorize
from ..sphere.folds import fold_free_blend
from .sphere_to_surface import SphereToSurface

#: Stop when an iteration lowers the energy by less than this fraction of it.
RTOL = 1e-4

#: Largest number of conjugate-gradient iterations of the global step.
CG_ITERATIONS = 8

#: Relative residual of the conjugate gradients of the global step.
CG_TOL = 1e-3

#: Smallest cosine between the normals of surface 2 under a triangle's three images for the
#: local step to trust their sum as the side the image should face (:meth:`SurfaceARAP.normals`).
NORMALS_AGREE = 0.5

#: The robust penalty's scale ``eps`` that ``robust_scale="auto"`` of
#: :func:`igl_spheremap.surface_map` uses where the map is near-isometric
#: (:func:`auto_robust_scale`; README, "Maps between surfaces").
AUTO_ROBUST_SCALE = 0.01

#: The largest area-weighted median ``|J - R|`` of a map between two surfaces that
#: :func:`auto_robust_scale` takes for near-isometric (``docs/decisions.md``).
NEAR_ISOMETRIC = 0.1

#: The smallest ratio of the 90th to the 50th area-weighted percentile of ``|J - R|`` of the
#: robust penalty's map that :func:`piecewise_rigid` takes for a map rigid but at a few places
#: (``docs/decisions.md``).
PIECEWISE_RIGID = 6.0

#: Edge selection ``E = X S`` of a triangle's corners (a, b, c): ``[x_b - x_a, x_c - x_a]``.
EDGES = np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]])


def to_sphere_scale(V, F):
    """``V`` scaled to total area ``4 pi`` ((n, 3) float64)."""
    V = np.asarray(V, dtype=np.float64)
    return V * np.sqrt(SPHERE_AREA / (igl.doublearea(V, F).sum() / 2.0))


def arap_terms(J, normals, oriented=None):
    """Per-face ARAP distortion and closest rotations of the Jacobians ``J`` (m, 3, 2).

    Parameters
    ----------
    J : (m, 3, 2) float64 array
    normals : (m, 3) float64 array
        Unit normals of surface 2 under each image (for collapsed images and the
        image's orientation).
    oriented : (m,) bool array, optional
        Where ``normals`` tell the image's orientation (default: nowhere; see
        :meth:`SurfaceARAP.normals`).

    Returns
    -------
    value : (m,) float64 array
        ``|J - R|^2`` (``sum_i (s_i - 1)^2`` over the singular values where the
        image keeps its orientation).
    R : (m, 3, 2) float64 array
        ``J (J^T J)^(-1/2)``, the map with orthonormal columns closest to ``J``
        (a rotation into the image's plane); for a collapsed image or an ``oriented``
        one turned over against ``normals`` (``(J e1 x J e2) . n <= 0``), the closest
        rotation of ``T^T J`` into the tangent plane ``T`` of ``normals``.
    """
    j1, j2 = J[:, :, 0], J[:, :, 1]
    a, b, c = (np.einsum("ij,ij->i", x, y) for x, y in ((j1, j1), (j1, j2), (j2, j2)))
    q = np.sqrt(np.maximum(a * c - b * b, 0.0))  # s1 s2
    s_sum = np.sqrt(a + c + 2.0 * q)  # s1 + s2
    den = (a + q) * (c + q) - b * b
    # an image turned over against surface 2 (chordal triangles over curved or crowded parts
    # can be, though the spherical map is fold-free) gets a rotation, not the reflection
    # J (J^T J)^(-1/2), which would make its flip free of cost
    good = den > 1e-12 * (a + c) ** 2
    if oriented is not None:
        good &= ~oriented | (np.einsum("ij,ij->i", cross_rows(j1, j2), normals) > 0)
    R = np.empty_like(J)
    g = np.flatnonzero(good)
    # sqrt(C) = (C + q I) / (s1 + s2) for C = J^T J, so R = J (C + q I)^-1 (s1 + s2)
    inv = np.stack([np.stack([c[g] + q[g], -b[g]], -1), np.stack([-b[g], a[g] + q[g]], -1)], 1)
    R[g] = J[g] @ (inv * (s_sum[g] / den[g])[:, None, None])
    other = np.flatnonzero(~good)
    if other.size:
        T = tangent_bases(normals[other])
        R[other] = T @ _rotations_2d(np.transpose(T, (0, 2, 1)) @ J[other])
    value = np.sum((J - R) ** 2, axis=(1, 2))
    return value, R


def _rotations_2d(A):
    """Closest rotations (det +1) to the 2 x 2 matrices ``A`` ((q, 2, 2) float64)."""
    th = np.arctan2(A[:, 1, 0] - A[:, 0, 1], A[:, 0, 0] + A[:, 1, 1])
    c, s = np.cos(th), np.sin(th)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], axis=1)


def robust_penalty(d, scale):
    """The pseudo-Huber penalty of the per-face ARAP distortions ``d`` (m,) and its slope.

    ``psi(d) = 2 eps (sqrt(d + eps^2) - eps)`` of ``d = |J - R|^2`` with ``eps = scale``: about
    ``d`` where ``|J - R|`` is below ``eps`` (plain ARAP), about ``2 eps |J - R|`` above it, so
    that the energy charges large distortions by their size, not its square, and a map that
    keeps most faces rigid and bends few (an articulated pose change) costs less than one
    that spreads the same bend thinly (Charbonnier, Blanc-Feraud, Aubert, Barlaud,
    "Deterministic edge-preserving regularization in computed imaging", IEEE TIP 6(2) 1997;
    a sparsity prior on non-rigid deformations: Yang, Li, Li, Lai, "Sparse non-rigid
    registration of 3D shapes", SGP 2015).  ``psi`` is concave in ``d``, so the weighted ARAP
    energy with the weights ``psi'(d)`` at the current map lies above it and touches it there:
    a step that lowers the weighted energy lowers the penalty (iteratively reweighted least
    squares, a majorization-minimization).

    Parameters
    ----------
    d : (m,) float64 array
        ``|J - R|^2`` per face (:func:`arap_terms`).
    scale : float or None
        ``eps`` (a stretch, dimensionless); None: plain ARAP (``psi(d) = d``, slope 1).

    Returns
    -------
    psi, slope : (m,) float64 arrays
        ``slope = psi'(d) = eps / sqrt(d + eps^2)`` in ``(0, 1]``.
    """
    if scale is None:
        return d, np.ones_like(d)
    root = np.sqrt(d + scale * scale)
    return 2.0 * scale * (root - scale), scale / root


def auto_robust_scale(problem, U, face):
    """The robust penalty's scale for a map that is near-isometric, else None, and the measure.

    The robust penalty (:func:`robust_penalty`) models a deformation that is rigid but for a
    few places, as between poses of one body, whose joints take the bend: there it keeps
    the limbs rigid.  Where the deformation stretches the surface broadly (a smooth
    non-isometric bend, two species) the distortion is spread by nature, and a penalty that
    concentrates it is wrong.  The two are told apart by the map reached so far: the
    area-weighted median ``|J - R|`` over surface 1's faces (:meth:`SurfaceARAP.median_stretch`)
    is a few percent between poses of one body and about a fifth or more otherwise
    (``docs/decisions.md``).

    Parameters
    ----------
    problem : SurfaceARAP
    U : (n1, 3) float64 array
        Surface 1's spherical map.
    face : (n1,) int64 array
        Faces of surface 2's map to start the point location from.

    Returns
    -------
    scale : float or None
        :data:`AUTO_ROBUST_SCALE` where the median is below :data:`NEAR_ISOMETRIC`, else None.
    median : float
        The median ``|J - R|`` (a stretch, dimensionless).
    """
    median = problem.median_stretch(U, face)
    return (AUTO_ROBUST_SCALE if median < NEAR_ISOMETRIC else None), median


def piecewise_rigid(problem, U, face):
    """Whether the robust penalty's map ``U`` is rigid but at a few places, and the measure.

    :func:`auto_robust_scale` tells near-isometric pairs by the map before the robust stage;
    a pair of two bodies of different shape can be as near-isometric by that measure as two
    poses of one body, but its deformation stretches everywhere, and the penalty, which
    concentrates the stretch, then moves the map off the true one.  The penalty's own map tells
    them apart: between poses it keeps most of the surface rigid and bends the joints, so
    ``|J - R|`` is concentrated (its area-weighted 90th percentile 7-9 times its median on
    the human pose pair), while on a stretched body it cannot and the ratio stays 3.4-5.1
    (``docs/decisions.md``).

    Parameters
    ----------
    problem : SurfaceARAP
        Plain (:func:`robust_penalty` off); only its distortions are used.
    U : (n1, 3) float64 array
        Surface 1's spherical map after the robust stage.
    face : (n1,) int64 array
        Faces of surface 2's map to start the point location from.

    Returns
    -------
    rigid : bool
        The ratio is at least :data:`PIECEWISE_RIGID`.
    ratio : float
        The 90th over the 50th area-weighted percentile of ``|J - R|``.
    """
    q50, q90 = problem.stretch_quantiles(U, face, [0.5, 0.9])
    ratio = float(q90 / max(q50, 1e-300))
    return ratio >= PIECEWISE_RIGID, ratio


def inverse_distortion(V1, F1, U1, V2, F2, U2):
    """The distortion of the map from surface 2 to surface 1 that the spherical maps ``U1`` of
    surface 1 and ``U2`` of surface 2 define: :class:`SurfaceARAP`'s energy with the surfaces'
    roles swapped, no landmarks (float).

    ARAP charges a triangle the map crushes at most twice its area, so a misaligned map
    1 -> 2 that crushes parts of surface 1 can cost no more than the right one; its inverse
    stretches them, which ARAP charges in full.  Starts are therefore compared by both
    directions (a symmetric distortion, as in Schmidt, Born, Campen, Kobbelt, TOG 2019).

    Parameters
    ----------
    V1, F1, U1 : (n1, 3) float64, (m1, 3) int64, (n1, 3) float64 arrays
        Surface 1 (at area ``4 pi``) and its fold-free spherical map (unit rows).
    V2, F2, U2 : (n2, 3) float64, (m2, 3) int64, (n2, 3) float64 arrays
        Surface 2 (at area ``4 pi``) and its spherical map.

    Returns
    -------
    float
    """
    phi1 = SphereToSurface(U1, F1, V1)
    none = (np.zeros(0, dtype=np.int64), np.zeros((0, 3)), 0.0)
    prob = SurfaceARAP(V2, F2, phi1, np.zeros(V2.shape[0], dtype=bool), none, 0.0)
    return prob.evaluate(U2, phi1.start(U2))[0]


def checked_robust_scale(robust_scale):
    """``robust_scale`` of :func:`igl_spheremap.surface_map` checked: ``"auto"``, None or a float.

    Parameters
    ----------
    robust_scale : object

    Returns
    -------
    "auto", None or float

    Raises
    ------
    ValueError
        Anything else than ``"auto"``, None or a finite number above 0.
    """
    if robust_scale is None or (isinstance(robust_scale, str) and robust_scale == "auto"):
        return robust_scale
    value = np.nan
    if not isinstance(robust_scale, str):
        try:
            value = float(robust_scale)
        except (TypeError, ValueError):
            pass
    if not (np.isfinite(value) and value > 0):
        raise ValueError(f"robust_scale must be 'auto', None or finite and > 0, got "
                         f"{robust_scale!r}")
    return value


class SurfaceARAP:
    """The ARAP problem of surface 1 onto surface 2 (module doc); the state of :func:`refine`.

    Parameters
    ----------
    V1, F1 : arrays
        Surface 1 ((n1, 3) float64, (m1, 3) int64 oriented outward), any scale.
    phi : SphereToSurface
        Surface 2 through its spherical map, surface 2 scaled to area ``4 pi``.
    fixed : (n1,) bool array
        Vertices that do not move (hard landmarks already on their targets).
    springs : tuple
        ``(at, to, stiffness)``: vertices (k,) of surface 1 pulled toward points
        (k, 3) of surface 2 (scaled like ``phi``) with the stiffness (float).
    proximal : float
        Weight of ``A_i |X_i - X_i^current|^2`` in the global step (a damping).
    descriptor : igl_spheremap.uses.descriptors.DescriptorTerm, optional
        A penalty on the images added to the energy; the global step takes its
        Gauss-Newton model (a 2 x 2 block per free vertex).
    solver : {"direct", "cholmod", "superlu"}
        Of the factorization of the 3-D solve
        (:func:`igl_spheremap.optimize.preconditioner.factorize`).
    rescale : bool
        Scale ``V1`` to area ``4 pi`` (False: ``V1`` is at surface 2's scale already, e.g.
        a coarse version of a surface that was, whose chordal faces have less area).
    orient : bool
        Give an image turned over against surface 2's normals a rotation, not its
        reflection (the local step, module doc).  Off for a coarse version of surface 1:
        a large coarse face over a fin or a bend faces away from the normals under its
        corners even at the exact map, which would then cost energy and be left.
    robust : float, optional
        The scale ``eps`` of :func:`robust_penalty` (a stretch); None: plain ARAP.

    Attributes
    ----------
    weights : (m1,) float64 array
        The faces' weights in the global step: 1, or with ``robust`` the penalty's slope
        at the map of the last step.
    """

    def __init__(self, V1, F1, phi, fixed, springs, proximal, descriptor=None, solver="direct",
                 rescale=True, orient=True, robust=None):
        self.phi = phi
        self.orient = orient
        self.solver = solver
        self.descriptor = descriptor
        self.F1 = np.ascontiguousarray(F1, dtype=np.int64)
        R1 = to_sphere_scale(V1, self.F1) if rescale else np.asarray(V1, dtype=np.float64)
        self.n = R1.shape[0]
        _, self.Dinv, self.area = triangle_frames(R1, self.F1)
        self.D = np.linalg.inv(self.Dinv)
        G = self.Dinv @ np.transpose(self.Dinv, (0, 2, 1))
        self.stiff = self.area[:, None, None] * (EDGES @ G @ EDGES.T)  # (m, 3, 3): cotan weights
        self.DG = self.D @ G @ EDGES.T  # (m, 2, 3)
        Mv = np.bincount(self.F1.ravel(), np.repeat(self.area / 3.0, 3), minlength=self.n)
        self.spring_at, self.spring_to, self.stiffness = springs
        self.prox = proximal * Mv
        self.free = np.flatnonzero(~np.asarray(fixed, dtype=bool))
        self.robust = robust
        self.weights = np.ones(self.F1.shape[0])
        self.assemble()
        self.cg_iterations = []

    def assemble(self):
        """The global step's matrix ``A`` (n, n) for the face weights :attr:`weights` (1 for
        plain ARAP), its rows and columns of the free vertices, and their 3-D version; the
        factorization is made again at the next step."""
        rows = np.repeat(self.F1, 3, axis=1).ravel()
        cols = np.tile(self.F1, (1, 3)).ravel()
        diagonal = self.prox.copy()
        np.add.at(diagonal, self.spring_at, self.stiffness)
        stiff = self.weights[:, None, None] * self.stiff
        self.A = (sp.csr_matrix((stiff.ravel(), (rows, cols)), shape=(self.n, self.n))
                  + sp.diags(diagonal)).tocsr()
        self.A_free = self.A[self.free][:, self.free].tocsc()
        self.A3 = sp.kron(self.A_free, sp.identity(3), format="csr")
        self.solve_free = None  # factorized at the next step (an evaluation needs none)

    def jacobians(self, X):
        """Jacobians (m, 3, 2) of the faces' maps onto the triangles of the images ``X``."""
        return np.einsum("mck,cj->mkj", X[self.F1], EDGES) @ self.Dinv

    def normals(self, face, w):
        """Unit normals (m1, 3) of surface 2 under the images of surface 1's faces (the
        normalized sum of its normals at the three corners' images,
        :meth:`~igl_spheremap.uses.sphere_to_surface.SphereToSurface.surface_normals`), and
        where they tell the image's orientation ((m1,) bool: those three normals agree
        within :data:`NORMALS_AGREE`; not across a thin fin or a sharp edge)."""
        n3 = self.phi.surface_normals(face, w)[self.F1]  # (m1, 3 corners, 3)
        N = n3.sum(axis=1)
        agree = np.min([np.einsum("ij,ij->i", n3[:, i], n3[:, (i + 1) % 3]) for i in range(3)],
                       axis=0) > NORMALS_AGREE
        return N / np.maximum(np.linalg.norm(N, axis=1, keepdims=True), 1e-300), agree

    def distortions(self, U, face):
        """``(face, X, d, R)`` of the map ``U``, located by walking from the faces ``face``:
        the images, ``d = |J - R|^2`` per face of surface 1 and the rotations
        (:func:`arap_terms`)."""
        face, w = self.phi.locate(U, face)
        X = self.phi.points(face, w)
        normals, agree = self.normals(face, w)
        per_face, R = arap_terms(self.jacobians(X), normals, agree if self.orient else None)
        return face, X, per_face, R

    def median_stretch(self, U, face):
        """The median of ``|J - R|`` over surface 1's faces weighted by their areas, at the map
        ``U`` (float, a stretch: 0 for a map that is rigid on every face)."""
        return float(self.stretch_quantiles(U, face, [0.5])[0])

    def stretch_quantiles(self, U, face, q):
        """Quantiles ``q`` ((p,) in [0, 1]) of ``|J - R|`` over surface 1's faces weighted by
        their areas, at the map ``U`` ((p,) float64, stretches: the smallest value with at least
        that share of the area at or below it)."""
        d = self.distortions(U, face)[2]
        order = np.argsort(d)
        cumulative = np.cumsum(self.area[order])
        at = np.searchsorted(cumulative, np.asarray(q, dtype=np.float64) * cumulative[-1])
        return np.sqrt(d[order][np.minimum(at, d.size - 1)])

    def evaluate(self, U, face):
        """``(value, face, X, R)`` of the map ``U``, located by walking from the faces ``face``."""
        face, X, per_face, R = self.distortions(U, face)
        D = X[self.spring_at] - self.spring_to
        value = float(self.area @ robust_penalty(per_face, self.robust)[0])
        value += self.stiffness * float(np.sum(D * D))
        if self.descriptor is not None:
            value += self.descriptor.value(face, X)
        return value, face, X, R

    def rhs(self, R):
        """``b`` (n, 3) of the global step ``A X = b`` for the rotations ``R`` (proximal term aside)."""
        B = (self.area * self.weights)[:, None, None] * (R @ self.DG)  # (m, 3 xyz, 3 corners)
        b = np.zeros((self.n, 3))
        for c in range(3):
            for k in range(3):
                b[:, k] += np.bincount(self.F1[:, c], B[:, k, c], minlength=self.n)
        np.add.at(b, self.spring_at, self.stiffness * self.spring_to)
        return b

    def direction(self, face, X, R):
        """The global step ``d`` (n, 3) in the tangent planes of surface 2, 0 at fixed vertices.

        With :attr:`robust`, the faces are first weighted by the penalty's slope at the images
        ``X`` (iteratively reweighted least squares, :func:`robust_penalty`)."""
        if self.robust is not None:
            d = np.sum((self.jacobians(X) - R) ** 2, axis=(1, 2))
            self.weights = robust_penalty(d, self.robust)[1]
            self.assemble()
        g = self.rhs(R) + self.prox[:, None] * X - self.A @ X
        idx, q = self.free, self.free.size
        T = self.phi.tangent_bases(face[idx])  # (q, 3, 2)
        rows = np.repeat(np.arange(3 * q).reshape(q, 3), 2, axis=1).ravel()
        cols = np.tile(np.arange(2 * q).reshape(q, 1, 2), (1, 3, 1)).ravel()
        Tm = sp.csr_matrix((T.ravel(), (rows, cols)), shape=(3 * q, 2 * q))
        K = (Tm.T @ self.A3 @ Tm).tocsr()
        r = Tm.T @ g[idx].ravel()
        if self.descriptor is not None:
            H, gd = self.descriptor.gauss_newton(face, X, idx, T)
            rows2 = np.repeat(np.arange(2 * q).reshape(q, 2), 2, axis=1).ravel()
            cols2 = np.tile(np.arange(2 * q).reshape(q, 1, 2), (1, 2, 1)).ravel()
            K = (K + sp.csr_matrix((H.ravel(), (rows2, cols2)), shape=K.shape)).tocsr()
            r = r - gd.ravel()

        if self.solve_free is None:
            A = self.A_free
            if self.descriptor is not None:
                A = A + sp.diags(self.descriptor.isotropic_stiffness(face[idx], idx))
            self.solve_free = factorize(A, self.solver)

        def precondition(v):  # T^T (A^-1 (x) I3) T: the 3-D solve, restricted to the planes
            return Tm.T @ self.solve_free((Tm @ v).reshape(q, 3)).ravel()

        its = [0]
        M = spla.LinearOperator(K.shape, matvec=precondition)
        delta, _ = spla.cg(K, r, x0=precondition(r), rtol=CG_TOL, maxiter=CG_ITERATIONS, M=M,
                           callback=lambda _: its.__setitem__(0, its[0] + 1))
        self.cg_iterations.append(its[0])
        d = np.zeros((self.n, 3))
        d[idx] = (Tm @ delta).reshape(q, 3)
        return d


def refine(problem, U1, face, *, iters=30, rtol=RTOL, substeps=4, betas=(1.0, 0.3, 0.1),
           callback=None):
    """Lower the ARAP distortion of the map surface 1 -> surface 2, keeping ``U1`` fold-free and
    the problem's fixed vertices where they are, to the bit.

    Parameters
    ----------
    problem : SurfaceARAP
    U1 : (n1, 3) float64 array
        Fold-free start.
    face : (n1,) int64 array
        Faces of surface 2's map containing ``U1`` (a start for the walks).
    iters : int
        Largest number of iterations.
    rtol : float
        Stop when an iteration lowers the energy by less than ``rtol`` times its value.
    substeps : int
        Of the walk along surface 2.
    betas : tuple of float
        Step lengths tried in turn (fractions of the global step) until one lowers
        the energy.
    callback : callable, optional
        ``callback(it, U1, value)`` before each iteration.

    Returns
    -------
    U1 : (n1, 3) float64 array
        Fold-free map whose energy is not above the start's.
    face : (n1,) int64 array
    history : list of float
        Energy of each accepted iterate, the start first.
    """
    val, face, X, R = problem.evaluate(U1, face)
    hist = [val]
    for it in range(iters):
        if callback is not None:
            callback(it, U1, val)
        d = problem.direction(face, X, R)
        U_new, _ = problem.phi.walk(U1, face, d, substeps)
        for beta in betas:
            U = moved_unit_rows(U1, U1 + beta * (U_new - U1))
            U_try = fold_free_blend(problem.F1, U1, U)[0]
            cand = problem.evaluate(U_try, face)
            if cand[0] < val:
                break
        if not cand[0] < val:
            break
        gain = val - cand[0]
        U1, (val, face, X, R) = U_try, cand
        hist.append(val)
        if gain < rtol * val:
            break
    return U1, face, hist

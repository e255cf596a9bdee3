"""Vertex correspondence by a functional map refined by ZoomOut, for starts without landmarks.

A functional map ``C`` (Ovsjanikov, Ben-Chen, Solomon, Butscher, Guibas, "Functional
maps", TOG 31(4) 2012) carries functions on surface 2, expanded in its first
Laplace–Beltrami eigenfunctions ``Phi2``, to functions on surface 1 (``Phi1``): for a
vertex map ``T`` from surface 1 to surface 2 pulling functions back (``f1 = f2 o T``),
``C = Phi1^T M1 Phi2[T]``.  It is fitted to what an intrinsic map preserves:

* descriptors: wave kernel signatures (Aubry, Schlickewei, Cremers, ICCV workshops 2011),
  ``C A2 ~ A1`` for their coefficients ``A``; where the map fitted to them contradicts given
  landmark pairs, also the wave kernel maps of each landmark (the same filters, centred at
  the landmark: Ovsjanikov, Mérigot, Mémoli, Guibas, "One point isometric matching with the
  heat kernel", SGP 2010, with the wave kernel of Aubry et al.), which tell apart what the
  surface's intrinsic symmetries make alike (a cat's front from its hind legs, left from right);
* the Laplacian: ``C Lambda2 ~ Lambda1 C``;
* products with the descriptors: ``C D2_f ~ D1_f C``, ``D_f = Phi^T M diag(f) Phi``
  (Nogneng, Ovsjanikov, "Informative descriptor preservation via commutativity for
  shape matching", CGF 36(2) 2017);
* orientation: ``C O2_f ~ O1_f C`` with ``O_f(g) = <n x grad f, grad g>`` (Ren, Poulenard,
  Wonka, Ovsjanikov, "Continuous and orientation-preserving correspondences via functional
  maps", TOG 37(6) 2018), which tells a map from its mirror image on a symmetric shape;

by L-BFGS (scipy).  ZoomOut (Melzi, Ren, Rodolà, Sharma, Wonka, Ovsjanikov, "ZoomOut:
spectral upsampling for efficient shape correspondence", TOG 38(6) 2019) then alternates
the vertex map (nearest neighbours of the rows of ``Phi1`` among those of ``Phi2 C^T``) and
the map ``C`` it induces, growing the basis a few functions at a time.

Each term is divided by its typical size so that the weights compare like with like, the
Laplacian term uses the resolvent mask (Ren, Melzi, Ovsjanikov, Wonka, "Structured
regularization of functional map computations", CGF 38(5) 2019), and the image of the
constant function is held fixed.  The peer ZoomOut of ``benchmarks/correspondence.py``
(pyfmaps) implements the same papers; docs/decisions.md compares the two.

The vertex map is neither bijective nor continuous; :mod:`igl_spheremap.uses.correspondence`
takes a few of its pairs as landmarks of a start and builds the bijection from there.
"""

from dataclasses import dataclass

import igl
import numpy as np
import scipy.sparse.linalg as sla
from scipy.optimize import minimize

from ..optimize.preconditioner import factorize

#: Shift-invert of the Laplace-Beltrami eigenproblem at ``-SHIFT`` (surface at area 1): far
#: enough below 0 that the shifted matrix ``-L + SHIFT M`` stays positive definite to
#: rounding (its Cholesky factorization), close enough that the low eigenpairs come first.
SHIFT = 1e-3

#: Eigenfunctions the functional map is fitted in.
FIT_SIZE = 30

#: ZoomOut: functions added per iteration, and iterations (the basis ends at
#: ``FIT_SIZE + ZOOM_STEP * ZOOM_ITERATIONS``).
ZOOM_STEP = 5
ZOOM_ITERATIONS = 16

#: Most vertices of each surface ZoomOut's iterations use (:func:`samples`): its vertex map
#: is a brute-force nearest-neighbour search, quadratic in the vertex count.
ZOOM_SAMPLES = 10000

#: Eigenpairs the wave kernel signature is built from (more than the fit uses: the
#: signature then resolves finer scales).
WKS_EIGENPAIRS = 128

#: Energies of the wave kernel signature, and the stride of those kept (every one kept
#: enters the descriptor, product and orientation terms).
WKS_ENERGIES = 100
WKS_STRIDE = 2

#: Width of the wave kernel signature's log-normal filters, in steps between energies.
WKS_WIDTH = 7.0

#: Energies of each landmark's wave kernel map (:func:`wave_kernel_maps`; docs/decisions.md).
WKM_ENERGIES = 10

#: A functional map contradicts the landmarks when more than this share of them land farther
#: than :data:`CONTRADICTION_DISTANCE` from their partners (:func:`contradicts`;
#: docs/decisions.md).
CONTRADICTED_SHARE = 0.2

#: Euclidean distance on surface 2 at area 1 (a lower bound of the geodesic one over
#: ``sqrt(area)``): a landmark this far from its partner sits on another part of the surface.
CONTRADICTION_DISTANCE = 0.1

#: Exponent of the resolvent Laplacian mask (Ren et al. 2019, module doc).
RESOLVENT_GAMMA = 0.5

#: Weights of the descriptor, Laplacian, product and orientation terms (each term is
#: first divided by its typical size, :func:`fit_functional_map`).
WEIGHTS = (1.0, 1e-1, 1e0, 1e0)


@dataclass
class LaplaceBasis:
    """The first eigenpairs of a surface's Laplace–Beltrami operator (surface scaled to area 1).

    Attributes
    ----------
    evals : (K,) float64 array
        Increasing, the first 0.
    evecs : (n, K) float64 array
        Orthonormal in the mass matrix.
    mass : (n,) float64 array
        Voronoi vertex areas (they sum to 1).
    V, F : arrays
        The surface at area 1 ((n, 3) float64, (m, 3) int64).
    """

    evals: np.ndarray
    evecs: np.ndarray
    mass: np.ndarray
    V: np.ndarray
    F: np.ndarray


def laplace_basis(V, F, count):
    """The first ``count`` eigenpairs of ``-L phi = lambda M phi`` (cotangent Laplacian ``L``,
    Voronoi mass ``M``) of the mesh scaled to area 1, by ``scipy.sparse.linalg.eigsh`` in
    shift-invert mode, the shifted matrix factorized by
    :func:`igl_spheremap.optimize.preconditioner.factorize` (:class:`LaplaceBasis`)."""
    F = np.ascontiguousarray(F, dtype=np.int64)
    V = np.asarray(V, dtype=np.float64)
    V = V / np.sqrt(igl.doublearea(V, F).sum() / 2.0)
    L = igl.cotmatrix(V, F)
    M = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_VORONOI)
    count = min(count, V.shape[0] - 1)
    shift = -SHIFT  # below the spectrum, so that -L - shift M is positive definite in floats
    solve = factorize((-L - shift * M).tocsc())  # CHOLMOD when installed
    OPinv = sla.LinearOperator(L.shape, matvec=solve, dtype=np.float64)
    evals, evecs = sla.eigsh(-L.tocsc(), k=count, M=M.tocsc(), sigma=shift, which="LM",
                             v0=np.ones(V.shape[0]), OPinv=OPinv)
    order = np.argsort(evals)
    return LaplaceBasis(np.maximum(evals[order], 0.0), evecs[:, order], M.diagonal(), V, F)


def _wave_filters(basis, energies, eigenpairs, stride=1):
    """``(phi, filt)``: the eigenfunctions ``1 .. eigenpairs - 1`` (n, K-1) and the wave
    kernel's log-normal filters of their eigenvalues at log-spaced energies (every
    ``stride``-th kept) ((K-1, p); Aubry et al. 2011)."""
    lam = basis.evals[1:eigenpairs]
    log_lam = np.log(np.maximum(lam, 1e-12))
    lo, hi = log_lam[0], log_lam[-1]
    sigma = WKS_WIDTH * (hi - lo) / energies
    e = np.linspace(lo + 2 * sigma, hi - 2 * sigma, energies)[::stride]
    filt = np.exp(-(e[None, :] - log_lam[:, None]) ** 2 / (2 * sigma ** 2))
    return basis.evecs[:, 1:eigenpairs], filt


def _unit_columns(W, mass):
    return W / np.sqrt(mass @ W ** 2)


def wave_kernel_signatures(basis, energies=WKS_ENERGIES, eigenpairs=WKS_EIGENPAIRS,
                           stride=WKS_STRIDE):
    """Wave kernel signatures (n, ceil(energies / stride)) from the first ``eigenpairs``
    eigenpairs at log-spaced energies (every ``stride``-th kept), each column scaled to unit
    norm in the mass matrix (Aubry et al. 2011; the constant eigenfunction left out)."""
    phi, filt = _wave_filters(basis, energies, eigenpairs, stride)
    return _unit_columns((phi ** 2) @ filt / filt.sum(axis=0), basis.mass)


def wave_kernel_maps(basis, at, energies=WKM_ENERGIES, eigenpairs=WKS_EIGENPAIRS):
    """The wave kernel maps of the vertices ``at``: ``W[x, (l, e)] = sum_i f_e(lambda_i)
    phi_i(at_l) phi_i(x)``, the wave kernel between ``at_l`` and every vertex ``x`` at each of
    ``energies`` log-spaced energies (the filters of :func:`wave_kernel_signatures`).

    Parameters
    ----------
    basis : LaplaceBasis
    at : (k,) int array
        Vertices (landmarks), ``k >= 1``.
    energies, eigenpairs : int

    Returns
    -------
    (n, k * energies) float64 array
        Columns grouped by vertex of ``at``, each scaled to unit norm in the mass matrix; an
        isometry that maps ``at`` to ``at'`` maps these to the maps of ``at'``.
    """
    phi, filt = _wave_filters(basis, energies, eigenpairs)
    W = np.concatenate([phi @ (filt * phi[v][:, None]) / filt.sum(axis=0)
                        for v in np.asarray(at, dtype=np.int64)], axis=1)
    return _unit_columns(W, basis.mass)


def orientation_operators(basis, D, size):
    """``O_f`` (p, size, size) for each column ``f`` of ``D`` (n, p): ``<n x grad f, grad g>``
    in the basis (Ren et al. 2018), ``O_ij = int phi_i <n x grad f, grad phi_j>`` with face
    means of ``phi_i`` (the mass-weighted projection of the vertex operator that averages
    the face values over the adjacent faces)."""
    V, F, Phi = basis.V, basis.F, basis.evecs[:, :size]
    G = igl.grad(V, F)
    m = F.shape[0]
    N = igl.per_face_normals(V, F, np.array([0.0, 0.0, 1.0]))
    area = igl.doublearea(V, F) / 2.0
    gphi = np.asarray(G @ Phi).reshape(3, m, size)  # (3, m, size)
    gD = np.asarray(G @ D).reshape(3, m, D.shape[1])  # (3, m, p)
    rot = np.cross(N[:, None, :], np.moveaxis(gD, 0, 2))  # (m, p, 3)
    face_mean = Phi[F].mean(axis=1) * area[:, None]  # (m, size)
    return sum(triple_products(face_mean, gphi[c], rot[:, :, c]) for c in range(3))


def triple_products(A, B, D, chunk=4096):
    """``T[p, i, j] = sum_n A[n, i] B[n, j] D[n, p]`` ((p, a, b) float64) for ``A`` (n, a),
    ``B`` (n, b), ``D`` (n, p): one matrix product per block of ``chunk`` rows."""
    a, b = A.shape[1], B.shape[1]
    out = np.zeros((a * b, D.shape[1]))
    for s in range(0, A.shape[0], chunk):
        X = (A[s:s + chunk, :, None] * B[s:s + chunk, None, :]).reshape(-1, a * b)
        out += X.T @ D[s:s + chunk]
    return out.T.reshape(D.shape[1], a, b)


def _operators(basis, D, size):
    """Descriptor coefficients (size, p), product operators and orientation operators
    ((p, size, size) each) of the descriptors ``D`` (n, p)."""
    Phi = basis.evecs[:, :size]
    MPhi = basis.mass[:, None] * Phi
    A = MPhi.T @ D
    return A, triple_products(MPhi, Phi, D), orientation_operators(basis, D, size)


def resolvent_mask(evals1, evals2, gamma=RESOLVENT_GAMMA):
    """(k1, k2) penalty of ``C[i, j]`` for the Laplacian term: ``|R(lambda1_i) - R(lambda2_j)|^2``
    with the resolvent ``R(x) = 1 / (x^gamma - i)`` of the eigenvalues scaled by the largest
    (bounded, unlike ``(lambda1_i - lambda2_j)^2``; Ren et al. SGP 2019)."""
    scale = max(np.max(evals1), np.max(evals2))
    def resolvent(lam):
        t = (np.maximum(lam, 0.0) / scale) ** gamma
        return t / (t * t + 1), 1 / (t * t + 1)
    r1, i1 = resolvent(evals1)
    r2, i2 = resolvent(evals2)
    return (r1[:, None] - r2[None, :]) ** 2 + (i1[:, None] - i2[None, :]) ** 2


def _effective_count(A):
    """How many independent descriptors the coefficients ``A`` (k, p) hold: ``tr(G)^2 /
    ||G||^2`` of their Gram matrix without the constant mode."""
    G = A[1:].T @ A[1:]
    d = np.sum(G * G)
    return np.trace(G) ** 2 / d if d > 0 else 1.0


def fit_functional_map(basis1, basis2, D1, D2, size=FIT_SIZE, weights=WEIGHTS):
    """The functional map ``C`` (size, size) from surface 2's basis to surface 1's (module doc).

    Minimizes ``(wd Ed + wl El + wc Ec + wo Eo) / 2`` by L-BFGS from ``C = +-e_0 e_0^T``, the
    first column (the image of the constant) held there.  Each term is divided by its typical
    size so that the weights compare like with like: ``Ed = ||C A2 - A1||^2`` by
    ``||A2[1:]||^2 / p`` (``p`` the effective number of independent descriptors, ``tr(G)^2 /
    ||G||^2`` of their Gram matrix), ``El = sum mask * C^2`` (:func:`resolvent_mask`) by
    ``sum(mask) / size``, ``Ec = sum_f ||C P2_f - P1_f C||^2`` by its expectation for a random
    orthogonal ``C`` over ``p``, ``Eo = sum_f ||C O2_f - O1_f C||^2`` by
    ``sum_f (||O1_f||^2 + ||O2_f||^2) / p``.

    Parameters
    ----------
    basis1, basis2 : LaplaceBasis
    D1, D2 : (n1, p), (n2, p) float64 arrays
        Corresponding descriptors.
    size : int
    weights : tuple of 4 floats
        ``(wd, wl, wc, wo)``, relative (divided by their sum).

    Returns
    -------
    (size, size) float64 array
    """
    A1, P1, O1 = _operators(basis1, D1, size)
    A2, P2, O2 = _operators(basis2, D2, size)
    wd, wl, wc, wo = (w / sum(weights) for w in weights)
    p_eff = max(0.5 * (_effective_count(A1) + _effective_count(A2)), 1e-12)
    mask = resolvent_mask(basis1.evals[:size], basis2.evals[:size])
    wd /= np.sum(A2[1:] ** 2) / p_eff
    wl /= mask.sum() / size
    tr1, tr2 = np.trace(P1, axis1=1, axis2=2), np.trace(P2, axis1=1, axis2=2)
    wc /= max((np.sum(P1 ** 2) + np.sum(P2 ** 2) - 2 * np.sum(tr1 * tr2) / size) / p_eff,
              1e-300)
    wo /= (np.sum(O1 ** 2) + np.sum(O2 ** 2)) / p_eff

    def commutator(C, X2, X1):  # value and gradient of sum_f ||C X2_f - X1_f C||^2 / 2
        S = C[None] @ X2 - X1 @ C[None]
        return 0.5 * np.sum(S * S), np.sum(S @ np.swapaxes(X2, 1, 2) - np.swapaxes(X1, 1, 2) @ S,
                                            axis=0)

    def energy(x):
        C = x.reshape(size, size)
        R = C @ A2 - A1
        ec, gc = commutator(C, P2, P1)
        eo, go = commutator(C, O2, O1)
        value = 0.5 * (wd * np.sum(R * R) + wl * np.sum(mask * C * C)) + wc * ec + wo * eo
        grad = wd * R @ A2.T + wl * mask * C + wc * gc + wo * go
        grad[:, 0] = 0.0
        return value, grad.ravel()

    C0 = np.zeros((size, size))
    C0[0, 0] = np.sign(basis1.evecs[0, 0] * basis2.evecs[0, 0])
    res = minimize(energy, C0.ravel(), jac=True, method="L-BFGS-B",
                   options=dict(maxiter=15000, ftol=1e7 * np.finfo(float).eps, gtol=1e-5))
    return res.x.reshape(size, size)


def vertex_map(Phi1, Phi2, C):
    """Partners on surface 2 ((n1,) int64, rows of ``Phi2``) of the rows of ``Phi1`` for the
    functional map ``C`` (k1, k2): nearest neighbours of the rows of ``Phi1`` (n1, >= k1)
    among the rows of ``Phi2 C^T`` (``Phi2`` (n2, >= k2)).

    ``Phi1 C ~ Pi Phi2`` for the pull-back ``Pi`` of the vertex map; for an orthogonal ``C``
    this is ``Phi1 ~ Pi Phi2 C^T``, and the second form compares the rows in surface 1's own
    spectral embedding, which does not shrink with ``C`` (a fitted ``C`` is far from
    orthogonal: its rows on left-right antisymmetric functions are near 0, and ``Phi1 C``
    loses what tells the sides apart)."""
    k1, k2 = C.shape
    return nearest_rows(Phi1[:, :k1], Phi2[:, :k2] @ C.T)


def nearest_rows(X, Y, chunk=2048):
    """For each row of ``X`` (n, k) the index of the nearest row of ``Y`` (m, k) ((n,) int64),
    by brute force in blocks (the largest ``x.y - |y|^2 / 2``, single precision): in ZoomOut's
    30 to 110 dimensions a k-d tree prunes nothing and is several times slower than matrix
    products.  Each block's products are shifted in place, with no second array of the
    block's size (the same partners, in less time: docs/decisions.md)."""
    X = np.asarray(X, dtype=np.float32)
    Y = np.ascontiguousarray(Y, dtype=np.float32)
    half = 0.5 * np.einsum("ij,ij->i", Y, Y)
    out = np.empty(X.shape[0], dtype=np.int64)
    for a in range(0, X.shape[0], chunk):
        P = X[a:a + chunk] @ Y.T
        P -= half
        out[a:a + chunk] = np.argmax(P, axis=1)
    return out


def samples(n, count=None):
    """Vertices ZoomOut runs on ((s,) int64, increasing): all ``n`` when ``n <= count``
    (default :data:`ZOOM_SAMPLES`), else ``count`` drawn uniformly (fixed seed)."""
    count = ZOOM_SAMPLES if count is None else count
    if n <= count:
        return np.arange(n, dtype=np.int64)
    return np.sort(np.random.default_rng(0).choice(n, count, replace=False)).astype(np.int64)


def zoomout(basis1, basis2, C, step=ZOOM_STEP, iterations=ZOOM_ITERATIONS):
    """ZoomOut (Melzi et al. 2019) from ``C``: the functional map ((k, k) float64) after
    growing the basis by ``step`` functions ``iterations`` times.

    Each iteration takes the vertex map (:func:`vertex_map`) of surface 1's vertices
    (:func:`samples` of them) among surface 2's (:func:`samples`) and the functional map
    it induces, the mass-weighted least-squares ``C`` with ``Phi1 C ~ Phi2[T]`` on those
    vertices (``Phi1^T M1 Phi2[T]`` when they are all of them; ZoomOut's paper subsamples
    the same way for speed)."""
    S1, S2 = samples(basis1.evecs.shape[0]), samples(basis2.evecs.shape[0])
    Phi1, Phi2, w = basis1.evecs[S1], basis2.evecs[S2], basis1.mass[S1][:, None]
    size = C.shape[0]
    for _ in range(iterations):
        T = vertex_map(Phi1, Phi2, C)
        size = min(size + step, Phi1.shape[1], Phi2.shape[1])
        P = Phi1[:, :size]
        C = np.linalg.solve(P.T @ (w * P), (w * P).T @ Phi2[T, :size])
    return C


def contradicts(basis1, basis2, C, landmarks):
    """Whether the functional map ``C`` sends more than :data:`CONTRADICTED_SHARE` of the
    landmarks of surface 1 farther than :data:`CONTRADICTION_DISTANCE` from their partners
    (Euclidean, on ``basis2.V``, the surface at area 1).

    Parameters
    ----------
    basis1, basis2 : LaplaceBasis
    C : (k, k) float64 array
    landmarks : tuple of two (l,) int arrays
        Corresponding vertices of surface 1 and 2 (``l >= 1``).

    Returns
    -------
    bool
    """
    l1, l2 = (np.asarray(x, dtype=np.int64) for x in landmarks)
    T = vertex_map(basis1.evecs[l1], basis2.evecs, C)
    far = np.linalg.norm(basis2.V[T] - basis2.V[l2], axis=1) > CONTRADICTION_DISTANCE
    return bool(np.mean(far) > CONTRADICTED_SHARE)


def spectral_correspondence(V1, F1, V2, F2, at=None, landmarks=None):
    """Vertex map from surface 1 to surface 2 by a functional map refined by ZoomOut.

    Parameters
    ----------
    V1, F1, V2, F2 : arrays
        Two closed triangle meshes ((n1, 3), (m1, 3), (n2, 3), (m2, 3)); any scale.
    at : (p,) array_like of int, optional
        Vertices of surface 1 whose partners are wanted (default: all).
    landmarks : tuple of two (k,) int arrays, optional
        Corresponding vertices of surface 1 and 2.  When the map fitted to the wave kernel
        signatures :func:`contradicts` them, it is fitted again with their wave kernel maps
        (:func:`wave_kernel_maps`) among the descriptors.  Only then: where the signatures
        alone agree with the landmarks, their map was as good or better on the benchmark
        pairs, and the second fit costs as much as the first (docs/decisions.md).

    Returns
    -------
    (p,) int64 array
        For each vertex of surface 1 in ``at``, a vertex of surface 2.

    Notes
    -----
    The map is as good as the surfaces are near-isometric: poses of one body, not two
    species (module doc for the method and its sources).
    """
    count = max(FIT_SIZE + ZOOM_STEP * ZOOM_ITERATIONS, WKS_EIGENPAIRS)
    b1, b2 = laplace_basis(V1, F1, count), laplace_basis(V2, F2, count)
    size = min(FIT_SIZE, b1.evals.size, b2.evals.size)  # small meshes have fewer eigenpairs
    D1, D2 = wave_kernel_signatures(b1), wave_kernel_signatures(b2)
    C = zoomout(b1, b2, fit_functional_map(b1, b2, D1, D2, size=size))
    if landmarks is not None and len(landmarks[0]) and contradicts(b1, b2, C, landmarks):
        D1 = np.hstack([D1, wave_kernel_maps(b1, landmarks[0])])
        D2 = np.hstack([D2, wave_kernel_maps(b2, landmarks[1])])
        C = zoomout(b1, b2, fit_functional_map(b1, b2, D1, D2, size=size))
    at = np.arange(b1.evecs.shape[0]) if at is None else np.asarray(at, dtype=np.int64)
    return vertex_map(b1.evecs[at], b2.evecs, C)

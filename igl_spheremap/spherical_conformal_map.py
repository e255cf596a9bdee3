"""Algorithm 2 of the paper end to end: Gauss map, Algorithm 1, star-map rounds."""

import time
import warnings

import igl
import numpy as np
from scipy.spatial import cKDTree

from .errors import SphericalMapWarning
from .gauss_map import gauss_map
from .harmonic_map import minimize_harmonic_energy
from .local_repair import local_repair as repair_folds_locally
from .metrics import count_folds, image_centroid
from .mobius import mobius_center
from .operators import laplacian, vertex_areas
from .preconditioner import one_blas_thread
from .result import Round, SphericalMapResult
from .star_map import star_map
from .untangle import untangle_folds
from .validation import validate_mesh

METHODS = {
    # The default: every deviation from the paper is listed in README.md.
    "folding_free": dict(laplacian_kind="intrinsic_delaunay", metric="H1", mobius=True,
                         keep_fold_free=True, untangle=True, local_repair=True, gtol=1e-5,
                         max_iter=5000, h1_solver="auto"),
    # Algorithms 1 and 2 as published: cotangent Laplacian, L2 gradient, no
    # Möbius normalization, plain line search.
    "paper": dict(laplacian_kind="cotan", metric="L2", mobius=False, keep_fold_free=False,
                  untangle=False, local_repair=False, gtol=1e-5, max_iter=20000,
                  h1_solver="auto"),
}


def spherical_conformal_map(V, F, *, method="folding_free", max_rounds=6, gtol=None,
                            max_iter=None, laplacian_kind=None, metric=None, mobius=None,
                            keep_fold_free=None, untangle=None, local_repair=None,
                            h1_solver=None, callback=None, progress=False):
    """Folding-free spherical conformal map of a closed genus-0 mesh (paper Algorithm 2).

    Stage 0 runs Algorithm 1 (:func:`igl_spheremap.harmonic_map`) from the Gauss
    map.  While the map has folded faces and fewer than ``max_rounds`` rounds
    ran, round ``k`` builds the star map of the weighted Laplace-Beltrami
    eigenfunctions of the current map (Section 4.2, Eqs. 20-27,
    :func:`igl_spheremap.star_map`) and reruns Algorithm 1 from it.

    ``method="folding_free"`` (default) differs from the paper as documented in
    README.md: intrinsic Delaunay cotangent Laplacian, H1-preconditioned
    gradient, Möbius normalization kept during the iteration, and, once a map
    is fold-free, a line search that never folds a face again.  When the
    folds left by stage 0 are isolated, round 1 is a *local repair*
    (:func:`igl_spheremap.local_repair.local_repair`: untangle them, then
    Algorithm 1 over the few rings around them) instead of a star-map round.
    ``method="paper"`` is the published algorithm.

    Parameters
    ----------
    V : (n, 3) float array
        Vertex positions (any units; the map does not depend on scale).
    F : (m, 3) int array
        Triangles of a closed, manifold, connected genus-0 mesh.  Inward
        orientation is fixed (and reported in ``orientation_flipped``).
    method : {"folding_free", "paper"}
    max_rounds : int
        Cap on folding-removal rounds (star-map projections).
    gtol : float, optional
        Stopping tolerance of Algorithm 1 on the RMS Riemannian gradient of the
        mesh scaled to area ``4 pi`` (default 1e-5).
    max_iter : int, optional
        Iteration cap of each Algorithm 1 run.
    laplacian_kind : {"intrinsic_delaunay", "cotan"}, optional
        Override the method's Laplacian.
    metric : {"H1", "L2"}, optional
        Override the method's gradient metric.
    mobius, keep_fold_free, untangle, local_repair : bool, optional
        Override the method's Möbius normalization, fold barrier (star
        rounds; a local repair always uses it), local untangling of star-map
        folds and local repair of isolated folds after stage 0 (see README,
        "How the default differs from the paper").
    h1_solver : {"auto", "direct", "amg", "cholmod", "superlu"}, optional
        How the H1 metric is inverted (see :func:`igl_spheremap.harmonic_map`);
        ``"auto"``: a sparse factorization (CHOLMOD if scikit-sparse is
        installed, else SuperLU) up to 50,000 vertices, an algebraic-multigrid
        V-cycle above.
    callback : callable, optional
        ``callback(round)`` with each finished :class:`igl_spheremap.Round`.
    progress : bool
        Show a tqdm progress bar of Algorithm 1 iterations on stderr.

    Returns
    -------
    SphericalMapResult
        ``U`` (n, 3) float64 unit vectors indexed like ``V``; ``folds``,
        ``converged``, ``success``, ``message``, ``rounds``, ...

    Raises
    ------
    MeshError
        If the mesh is invalid (see :func:`igl_spheremap.validate_mesh`).
    ValueError
        If ``method`` is unknown.
    RuntimeError
        If the eigensolver fails or a step produces non-finite values.

    Warns
    -----
    SphericalMapWarning
        If the returned map has folded faces or Algorithm 1 did not converge
        (the result says so too: ``success`` is False).
    """
    if method not in METHODS:
        raise ValueError(f"unknown method {method!r}; expected one of {sorted(METHODS)}")
    # BLAS calls here are small (n x 3 products, 3 x 3 solves, ARPACK's
    # Lanczos vectors): threads only add synchronization.
    with one_blas_thread():
        return _spherical_conformal_map(
            V, F, method=method, max_rounds=max_rounds, gtol=gtol, max_iter=max_iter,
            laplacian_kind=laplacian_kind, metric=metric, mobius=mobius,
            keep_fold_free=keep_fold_free, untangle=untangle, local_repair=local_repair,
            h1_solver=h1_solver, callback=callback, progress=progress)


def _spherical_conformal_map(V, F, *, method, max_rounds, gtol, max_iter, laplacian_kind, metric,
                             mobius, keep_fold_free, untangle, local_repair, h1_solver, callback,
                             progress):
    t0 = time.perf_counter()
    V_in = np.asarray(V, dtype=np.float64)
    mesh = validate_mesh(V, F)
    V, F = mesh.V, mesh.F
    opts = dict(METHODS[method])
    for key, val in (("gtol", gtol), ("max_iter", max_iter), ("laplacian_kind", laplacian_kind),
                     ("metric", metric), ("mobius", mobius), ("keep_fold_free", keep_fold_free),
                     ("untangle", untangle), ("local_repair", local_repair),
                     ("h1_solver", h1_solver)):
        if val is not None:
            opts[key] = val
    laplacian_used = opts.pop("laplacian_kind")
    L = laplacian(V, F, laplacian_used)
    untangle = opts.pop("untangle")
    repair_locally = opts.pop("local_repair")
    area = vertex_areas(V, F)
    area *= 4.0 * np.pi / area.sum()

    bar = None
    if progress:
        from tqdm.auto import tqdm
        bar = tqdm(desc="Algorithm 1", unit="it", leave=False)

    rounds = []
    U_init = gauss_map(V, F)
    Phi = lam = None
    reflected = False
    for k in range(max_rounds + 1):
        tr = time.perf_counter()
        folds_star = None
        if k == 1 and repair_locally:
            # Isolated folds of a converged map: repair them locally instead of
            # restarting from a star map (local_repair; not in the paper).
            start = rounds[-1].U
            if opts["mobius"]:
                start, _ = mobius_center(start, area)
            repaired = repair_folds_locally(L, area, F, start, **opts)
            if repaired is not None:
                U_init, res, region = repaired
                rnd = Round(index=k, kind="local", U_init=U_init, U=res.U, folds_before=0,
                            folds_after=count_folds(F, res.U), nit=res.nit,
                            converged=res.converged, message=res.message,
                            energy_history=res.energy_history,
                            grad_norm_history=res.grad_norm_history,
                            seconds=time.perf_counter() - tr, frozen=res.frozen,
                            region=int(region.sum()))
                rounds.append(rnd)
                if callback is not None:
                    callback(rnd)
                if rnd.folds_after == 0:
                    break
                continue
        if k > 0:
            U_init, Phi, lam, reflected = star_map(V, F, rounds[-1].U, L=L, area=area,
                                                   return_details=True)
            folds_star = count_folds(F, U_init)
            if folds_star and untangle:
                U_init, _ = untangle_folds(F, U_init)
        folds_init = count_folds(F, U_init)
        cb = None
        if bar is not None:
            bar.set_description(f"round {k} ({'star' if k else 'gauss'} map)")

            def cb(it, U, E, g):
                bar.update(1)
                bar.set_postfix(energy_4pi=f"{E / (4 * np.pi):.5f}", grad=f"{g:.1e}")
        run = dict(opts)
        # The fold barrier keeps a fold-free (star) map fold-free.  From a map
        # that still folds it would keep those faces folded and, measured on
        # pycortex (2 folds left after untangling), crawl at ~0.5 s per
        # iteration, so such rounds (and the Gauss-map round) run free.
        run["keep_fold_free"] = opts["keep_fold_free"] and k > 0 and folds_init == 0
        res = minimize_harmonic_energy(L, area, F, U_init, callback=cb, **run)
        if not np.all(np.isfinite(res.U)):
            raise RuntimeError(f"Algorithm 1 produced non-finite values in round {k}")
        rnd = Round(index=k, kind="star" if k else "gauss", U_init=U_init, U=res.U,
                    folds_before=folds_init, folds_after=res.folds, nit=res.nit,
                    converged=res.converged, message=res.message,
                    energy_history=res.energy_history, grad_norm_history=res.grad_norm_history,
                    seconds=time.perf_counter() - tr, Phi=Phi, eigenvalues=lam,
                    reflected=reflected, frozen=res.frozen, folds_star=folds_star)
        rounds.append(rnd)
        if callback is not None:
            callback(rnd)
        if rnd.folds_after == 0:
            break
    if bar is not None:
        bar.close()
    last = rounds[-1]
    U = last.U
    if opts["mobius"]:
        centered, _ = mobius_center(U, area)
        left = count_folds(F, centered)
        if left > last.folds_after and (untangle or repair_locally):
            # Re-centering can flip a near-degenerate sliver (pycortex: one
            # face of signed volume 8e-18): kernel moves of its vertices only.
            centered, left = untangle_folds(F, centered, max_rings=0)
        if left <= last.folds_after:
            U = centered
    folds = count_folds(F, U)
    nit = sum(r.nit for r in rounds)
    if folds:
        msg = f"{folds} folded faces remain after {len(rounds) - 1} folding-removal rounds"
    elif not last.converged:
        msg = f"fold-free, but Algorithm 1 did not converge: {last.message}"
    else:
        msg = f"fold-free after {len(rounds) - 1} folding-removal rounds; {last.message}"
    U_out = np.empty((V_in.shape[0], 3))
    U_out[mesh.vertex_index] = U
    if mesh.unreferenced.size:
        # Not part of the surface: each gets the image of its nearest surface vertex.
        _, nearest = cKDTree(V).query(V_in[mesh.unreferenced])
        U_out[mesh.unreferenced] = U[nearest]
    if folds or not last.converged:
        warnings.warn(f"spherical_conformal_map: {msg}", SphericalMapWarning, stacklevel=3)
    return SphericalMapResult(
        U=U_out, folds=folds, converged=last.converged, message=msg, rounds=rounds, nit=nit,
        energy=float(-0.5 * np.sum(U * (L @ U))),
        centroid_norm=float(np.linalg.norm(image_centroid(V, F, U))),
        min_image_area=float(igl.doublearea(U, F).min() / 2),
        orientation_flipped=mesh.orientation_flipped, seconds=time.perf_counter() - t0,
        options=dict(method=method, max_rounds=max_rounds, laplacian_kind=laplacian_used,
                     untangle=untangle, local_repair=repair_locally, **opts))

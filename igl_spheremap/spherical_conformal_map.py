"""Algorithm 2 of the paper end to end: Gauss map, Algorithm 1, star-map rounds."""

import time

import igl
import numpy as np

from .gauss_map import gauss_map
from .harmonic_map import minimize_harmonic_energy
from .metrics import count_folds, image_centroid
from .operators import laplacian, vertex_areas
from .result import Round, SphericalMapResult
from .star_map import star_map
from .validation import validate_mesh


def spherical_conformal_map(V, F, *, method="folding_free", max_rounds=6, gtol=1e-5,
                            max_iter=20000, callback=None):
    """Folding-free spherical conformal map of a closed genus-0 mesh (paper Algorithm 2).

    (Provisional docstring.)
    """
    t0 = time.perf_counter()
    mesh = validate_mesh(V, F)
    V, F = mesh.V, mesh.F
    paper = method == "paper"
    L = laplacian(V, F, "cotan" if paper else "intrinsic_delaunay")
    area = vertex_areas(V, F)
    area *= 4.0 * np.pi / area.sum()
    opts = dict(gtol=gtol, max_iter=max_iter, mobius_tol=None if paper else 1e-3,
                keep_fold_free=not paper)
    rounds = []
    U_init = gauss_map(V, F)
    Phi = lam = None
    reflected = False
    for k in range(max_rounds + 1):
        tr = time.perf_counter()
        if k > 0:
            U_init, Phi, lam, reflected = star_map(V, F, rounds[-1].U, L=L, area=area,
                                                   return_details=True)
        res = minimize_harmonic_energy(L, area, F, U_init, **opts)
        rnd = Round(index=k, kind="star" if k else "gauss", U_init=U_init, U=res.U,
                    folds_before=count_folds(F, U_init), folds_after=res.folds, nit=res.nit,
                    converged=res.converged, message=res.message,
                    energy_history=res.energy_history, grad_norm_history=res.grad_norm_history,
                    seconds=time.perf_counter() - tr, Phi=Phi, eigenvalues=lam,
                    reflected=reflected)
        rounds.append(rnd)
        if callback is not None:
            callback(rnd)
        if rnd.folds_after == 0:
            break
    U = rounds[-1].U
    folds = rounds[-1].folds_after
    conv = rounds[-1].converged
    msg = f"{folds} folded faces after {len(rounds) - 1} folding-removal rounds; " + rounds[-1].message
    U_out = np.empty((mesh.vertex_index.size + mesh.unreferenced.size, 3))
    U_out[mesh.vertex_index] = U
    return SphericalMapResult(
        U=U_out, folds=folds, converged=conv, message=msg, rounds=rounds,
        nit=sum(r.nit for r in rounds), energy=rounds[-1].energy,
        centroid_norm=float(np.linalg.norm(image_centroid(V, F, U))),
        min_image_area=float(igl.doublearea(U, F).min() / 2),
        orientation_flipped=mesh.orientation_flipped, seconds=time.perf_counter() - t0,
        options=dict(method=method, max_rounds=max_rounds, gtol=gtol, max_iter=max_iter))

"""Local fold repair of a harmonic map: untangle, then Algorithm 1 around the repair (not in the paper)."""

import numpy as np

from ..mesh.operators import dirichlet_energy
from ..mesh.topology import grow_region, vertex_adjacency
from ..optimize.harmonic import HarmonicEnergy
from ..optimize.minimize import minimize
from ..sphere.folds import count_folds
from .untangle import untangle_patches

#: Repair locally only when the untangled region (with its rings) holds at
#: most this share of the vertices; otherwise the folds are not isolated and
#: a star-map round (paper Section 4) is the better start (``docs/decisions.md``).
MAX_REGION_FRACTION = 0.1


def local_repair(L, area, F, U, options, *, rings=3, max_fraction=MAX_REGION_FRACTION):
    """Remove the folds of a harmonic map by local untangling and local re-minimization.

    Not in the paper.  When Algorithm 1 from the Gauss map converges with a few
    isolated folded faces (slivers on thin legs, a few faces of a fine remesh),
    the paper reruns Algorithm 1 from a
    global star map.  Here instead:

    1. :func:`igl_spheremap.folding.untangle.untangle_patches` makes the map fold-free
       by moving the vertices around the folded faces (Tutte patches, kernel moves,
       and where those leave folds untangled patches);
    2. the *region* = moved vertices plus ``rings`` edge rings around them;
    3. Algorithm 1 with the fold barrier (:func:`igl_spheremap.optimize.minimize.minimize`,
       ``fold_barrier=True``) re-minimizes the harmonic energy over the
       region, with every other vertex fixed (the region's rows of ``L``
       only involve the region and its fixed neighbors; fixed vertices pin the
       Möbius freedom, so no gauge applies).

    Away from the region the map stays the converged Algorithm 1 map.

    Parameters
    ----------
    L : (n, n) sparse matrix
        Laplacian of Algorithm 1 (negative semidefinite).
    area : (n,) float64 array
        Vertex areas (mesh scaled to total area ``4 pi``).
    F : (m, 3) int64 array
    U : (n, 3) float64 array
        Map with folded faces (unit rows), e.g. the result of Algorithm 1.
    options : MapOptions
        Algorithm 1's options (``gtol``, ``max_iter``, ``metric``, ``h1_solver``,
        ...); its stopping rule is then the RMS gradient over the region's free
        vertices and their fixed neighbors.
    rings : int
        Edge rings added around the untangled vertices.
    max_fraction : float
        Give up (return None) when the region has more than this share of the
        vertices.

    Returns
    -------
    None or tuple
        None when ``U`` has no folded face, untangling leaves folds or the
        region is too large, else
        ``(U_init, result, region, patched)``: the untangled map (n, 3), the
        :class:`igl_spheremap.optimize.result.Algorithm1Result` of the local Algorithm 1 with
        ``result.U`` the repaired map on all ``n`` vertices and
        ``result.energy`` / ``energy_history`` the harmonic energy of the whole
        map (``grad_norm_history`` is over the region), the (n,) bool mask
        of the vertices that were free to move, and whether untangled patches
        were kept (bool).
    """
    n = U.shape[0]
    folds = count_folds(F, U)
    if folds == 0 or folds > max_fraction * n:
        return None  # nothing to repair, or not isolated folds
    A = vertex_adjacency(F, n)
    U_init, left, patched = untangle_patches(F, U, adjacency=A)
    if left:
        return None
    region = grow_region(A, np.any(U_init != U, axis=1), rings)
    if region.sum() > max_fraction * n:
        return None
    # The region and its neighbors in L and in F (an intrinsic Laplacian has
    # edges that F has not, and F edges that it flipped); both are symmetric,
    # so the neighbors are the column indices of the region's rows.
    rows = np.flatnonzero(region)
    idx = np.union1d(rows, np.union1d(L.tocsr()[rows].indices, A[rows].indices))
    local = np.full(n, -1, dtype=np.int64)
    local[idx] = np.arange(idx.size)
    energy = HarmonicEnergy(L[idx][:, idx], area[idx], options.metric, options.h1_solver)
    res = minimize(energy, U_init[idx], local[F[region[F].any(axis=1)]], options,
                   fixed=~region[idx], fold_barrier=True)
    U_out = U_init.copy()
    U_out[region] = res.U[local[region]]  # fixed rows stay bit for bit
    res.U = U_out
    # The energies above are of the region's problem; every term of the whole
    # energy that it lacks joins two fixed vertices, so they differ by a constant.
    shift = dirichlet_energy(L, U_init) - res.energy_history[0]
    res.energy += shift
    res.energy_history = [e + shift for e in res.energy_history]
    return U_init, res, region, patched

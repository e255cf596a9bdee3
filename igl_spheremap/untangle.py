"""Local untangling of the few folded faces a star map can keep (not in the paper)."""

import igl
import numpy as np
import scipy.sparse as sp
import scipy.sparse.csgraph as csgraph
import scipy.sparse.linalg as spla

from .metrics import folded_faces


def _adjacency(F, n):
    E = igl.edges(F)
    A = sp.coo_matrix((np.ones(len(E)), (E[:, 0], E[:, 1])), shape=(n, n))
    return (A + A.T).tocsr()


def _tutte_patch(F, U, inside, faces):
    """Re-embed the vertices ``inside`` by a Tutte embedding in a gnomonic chart.

    Returns the new positions of the ``inside`` vertices, or None when the
    patch is not a disk, does not fit in one chart, or its boundary polygon is
    not strictly convex (then Tutte's theorem would not apply).
    """
    Fp = F[faces]
    verts = np.unique(Fp)
    local = -np.ones(U.shape[0], dtype=np.int64)
    local[verts] = np.arange(verts.size)
    Fl = local[Fp]
    E = igl.edges(Fl)
    if verts.size - E.shape[0] + Fl.shape[0] != 1:
        return None  # not a disk
    loops = igl.boundary_loop_all(Fl)
    if len(loops) != 1:
        return None
    loop = np.asarray(loops[0], dtype=np.int64)
    fixed = np.zeros(verts.size, dtype=bool)
    fixed[loop] = True
    if np.any(fixed & inside[verts]) or np.count_nonzero(~fixed) != np.count_nonzero(inside):
        return None
    P = U[verts]
    c = P.sum(axis=0)
    c /= np.linalg.norm(c)
    h = P @ c
    if h.min() <= 0.2:
        return None  # does not fit in one gnomonic chart
    e1 = np.cross(c, [1.0, 0.0, 0.0] if abs(c[0]) < 0.9 else [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(c, e1)
    Q = P / h[:, None]
    X = np.column_stack([Q @ e1, Q @ e2])
    A = _adjacency(Fl, verts.size)
    Lu = (sp.diags(np.asarray(A.sum(axis=1)).ravel()) - A).tocsr()
    free = ~fixed
    rhs = -Lu[free][:, fixed] @ X[fixed]
    Xf = spla.spsolve(Lu[free][:, free].tocsc(), rhs)
    Y = c + np.outer(Xf[:, 0], e1) + np.outer(Xf[:, 1], e2)
    return verts[free], Y / np.linalg.norm(Y, axis=1, keepdims=True)


def _fill_holes(A, region):
    """Add to ``region`` every vertex its boundary ring encloses.

    The vertices outside the region and its one-ring split into connected
    components; all but the largest (the rest of the mesh) are holes.
    """
    grown = region | ((A @ region.astype(np.float64)) > 0)
    rest = np.flatnonzero(~grown)
    if rest.size == 0:
        return region
    ncomp, labels = csgraph.connected_components(A[rest][:, rest], directed=False)
    if ncomp > 1:
        sizes = np.bincount(labels)
        region = region.copy()
        region[rest[labels != np.argmax(sizes)]] = True
    # Ring vertices with no neighbor outside the ring are enclosed too.
    outside = ~(region | grown)
    ring = grown & ~region
    enclosed = ring & ~((A @ outside.astype(np.float64)) > 0)
    return region | enclosed


def untangle_folds(F, U, max_rings=12):
    """Remove isolated folded faces by local Tutte re-embedding.

    Around each cluster of folded faces, the ``k``-ring patch (``k = 1, 2, ...,
    max_rings``) is mapped to the tangent plane by the gnomonic projection
    (central projection, which keeps the sign of every image triangle's
    orientation); if the patch is a disk whose boundary polygon is strictly
    convex, its interior vertices are replaced by the uniform-weight Tutte
    embedding with that boundary fixed, which is fold-free by Tutte's theorem,
    and projected back to the sphere.  Faces outside the patches are unchanged.
    The result is not conformal inside the patches; Algorithm 1 with the fold
    barrier polishes it afterwards.

    Parameters
    ----------
    F : (m, 3) int64 array
    U : (n, 3) float64 array
        Map with a few folded faces (unit rows).
    max_rings : int
        Largest patch radius, in edge rings around the folded faces.

    Returns
    -------
    U : (n, 3) float64 array
        Map with the untangled patches replaced (a copy).
    remaining : int
        Folded faces left.
    """
    U = np.array(U, dtype=np.float64, copy=True)
    n = U.shape[0]
    A = _adjacency(F, n)
    m = F.shape[0]
    VF = sp.csr_matrix((np.ones(3 * m), (F.ravel(), np.repeat(np.arange(m), 3))), shape=(n, m))
    for rings in range(1, max_rings + 1):
        folded = folded_faces(F, U)
        if not folded.any():
            return U, 0
        region = np.zeros(n, dtype=bool)
        region[F[folded].ravel()] = True
        for _ in range(rings):
            region |= (A @ region.astype(np.float64)) > 0
        region = _fill_holes(A, region)
        ncomp, labels = csgraph.connected_components(A[region][:, region], directed=False)
        idx = np.flatnonzero(region)
        for comp in range(ncomp):
            members = idx[labels == comp]
            inside = np.zeros(n, dtype=bool)
            inside[members] = True
            faces = np.unique(VF[members].indices)
            patch = _tutte_patch(F, U, inside, faces)
            if patch is None:
                continue
            verts, Y = patch
            old = U[verts].copy()
            U[verts] = Y
            if folded_faces(F[faces], U).any():
                U[verts] = old
    return U, int(np.count_nonzero(folded_faces(F, U)))

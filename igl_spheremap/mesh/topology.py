"""Topology of a triangle mesh: the checks of :func:`igl_spheremap.validate_mesh` (manifold,
closed, connected, orientable, genus 0) with the orientation repair, and the vertex graph
(adjacency, vertex-face incidence, regions grown by rings with their holes filled)."""

import igl
import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from ..errors import MeshError, plural


def _fail(problem, count, text):
    raise MeshError.invalid(problem, count, text)


def vertex_adjacency(F, n):
    """Vertex adjacency of the edges of ``F``: symmetric (n, n) csr_matrix, 1 per edge."""
    E = igl.edges(F)
    A = sp.coo_matrix((np.ones(len(E)), (E[:, 0], E[:, 1])), shape=(n, n))
    return (A + A.T).tocsr()


def vertex_face_incidence(F, n):
    """(n, m) scipy.sparse.csr_matrix with a 1 where vertex ``i`` is a corner of face ``f``."""
    m = F.shape[0]
    return sp.csr_matrix((np.ones(3 * m), (F.ravel(), np.repeat(np.arange(m), 3))), shape=(n, m))


def grow_region(A, region, rings=1):
    """``region`` (n,) bool grown by ``rings`` edge rings of the adjacency ``A`` (a new array)."""
    region = np.asarray(region, dtype=bool)
    for _ in range(rings):
        region = region | ((A @ region.astype(np.float64)) > 0)
    return region


def fill_holes(A, region, outside=None):
    """``region`` with every vertex its boundary ring encloses added ((n,) bool).

    The vertices outside the region and its one-ring split into connected
    components of the adjacency ``A``; all but the largest (the rest of the
    mesh) are holes, or with ``outside`` ((n,) bool: vertices known to lie
    beyond every hole, e.g. the rim of a submesh), all that contain none of
    them.  Ring vertices with no neighbor outside the ring are enclosed too.
    """
    grown = grow_region(A, region)
    rest = np.flatnonzero(~grown)
    if rest.size == 0:
        return region
    ncomp, labels = connected_components(A[rest][:, rest], directed=False)
    if ncomp > 1:
        if outside is None:
            holes = labels != np.argmax(np.bincount(labels))
        else:
            holes = ~np.isin(labels, labels[outside[rest]])
        region = region.copy()
        region[rest[holes]] = True
    beyond = ~(region | grown)
    ring = grown & ~region
    enclosed = ring & ~((A @ beyond.astype(np.float64)) > 0)
    return region | enclosed


def _sizes(counts, limit=8):
    return ", ".join(str(int(c)) for c in counts[:limit]) + (", ..." if len(counts) > limit else "")


def _interior_half_edges(uEC, uEE):
    """The two half-edges ``h1, h2`` of each interior edge (valence 2), from the
    unique edge -> half-edge map ``uEC, uEE`` of ``igl.unique_edge_map``
    (half-edge ``h = f + m c`` is opposite corner ``(f, c)``)."""
    start = uEC[:-1][np.diff(uEC) == 2]
    return uEE[start], uEE[start + 1]


def _fans_per_vertex(F, h1, h2, n):
    """Number of face fans around each vertex of an edge-manifold mesh.

    A vertex is manifold when this is 1: the definition of ``igl.is_vertex_manifold``,
    computed faster (``docs/decisions.md``) as the connected components of the
    graph joining the two corners at each end of every interior edge
    (half-edges ``h1, h2`` from :func:`_interior_half_edges`).
    """
    m = F.shape[0]
    a1, b1 = 3 * (h1 % m) + (h1 // m + 1) % 3, 3 * (h1 % m) + (h1 // m + 2) % 3
    a2, b2 = 3 * (h2 % m) + (h2 // m + 1) % 3, 3 * (h2 % m) + (h2 // m + 2) % 3
    Fr = F.ravel()  # corner 3 f + c sits at vertex F[f, c]
    same = Fr[a1] == Fr[a2]
    rows = np.concatenate([a1, b1])
    cols = np.concatenate([np.where(same, a2, b2), np.where(same, b2, a2)])
    G = sp.csr_matrix((np.ones(rows.size, np.int8), (rows, cols)), shape=(3 * m, 3 * m))
    k, label = connected_components(G, directed=False)
    vertex_of_fan = np.empty(k, np.int64)
    vertex_of_fan[label] = Fr
    return np.bincount(vertex_of_fan, minlength=n)


def check_topology(F, n, shared=None):
    """Edge- and vertex-manifold, closed, connected; returns E, uE, EMAP of igl.unique_edge_map.

    ``shared``, a callable giving (n,) bool (the vertices whose position another vertex
    shares), is called only for an open mesh: where at least half of the boundary vertices
    share a position, the boundary is a seam of split vertices (or the mesh a triangle soup),
    and the message says to merge them rather than to fill holes.
    """
    E, uE, EMAP, uEC, uEE = igl.unique_edge_map(F)
    valence = np.diff(uEC)
    if (valence > 2).any():
        k, e = int(np.count_nonzero(valence > 2)), np.flatnonzero(valence > 2)[0]
        _fail("nonmanifold_edge", k,
              f"{plural(k, 'edge')} shared by more than 2 faces (first: edge "
              f"{uE[e].tolist()} in {valence[e]} faces); repair with "
              "pymeshfix.MeshFix(V, F).repair() or cut them apart with igl.split_nonmanifold.")
    h1, h2 = _interior_half_edges(uEC, uEE)
    fans = _fans_per_vertex(F, h1, h2, n)
    if (fans > 1).any():
        k, v = int(np.count_nonzero(fans > 1)), np.flatnonzero(fans > 1)[0]
        _fail("nonmanifold_vertex", k,
              f"{plural(k, 'non-manifold vertex', 'non-manifold vertices')}"
              f" whose faces form several fans, e.g. a bowtie (first: vertex {v}, {fans[v]} fans);"
              " split with igl.split_nonmanifold or repair with pymeshfix.MeshFix(V, F).repair().")
    be = uE[valence == 1]
    if be.size:  # each boundary vertex has 2 boundary edges: graph components = loops
        bv, inv = np.unique(be, return_inverse=True)
        inv = inv.reshape(-1, 2)
        A = sp.csc_matrix((np.ones(inv.size, np.int64), (inv.ravel(), inv[:, ::-1].ravel())),
                          shape=(bv.size, bv.size))
        nloops, _, K = igl.connected_components(A)
        k = 0 if shared is None else int(np.count_nonzero(shared()[bv]))
        if 2 * k >= bv.size:
            fix = (f"but {k} of its {bv.size} boundary vertices share their position with "
                   "another vertex: the surface is split along seams (vertices duplicated, e.g. "
                   "at UV or normal seams) or a triangle soup (an STL file read by "
                   "igl.read_triangle_mesh); merge them rather than fill holes: V, _, _, F = "
                   "igl.remove_duplicate_vertices(V, F, 0.0) (or a small epsilon, e.g. 1e-9 "
                   "times the bounding-box diagonal, where the copies differ by rounding).")
        else:
            fix = ("close the holes, e.g. pymeshfix.MeshFix(V, F).repair() or a triangle fan per "
                   "loop of igl.boundary_loop_all.")
        _fail("boundary", be.shape[0],
              f"the mesh is open: {plural(be.shape[0], 'boundary edge')} in "
              f"{plural(nloops, 'boundary loop')} (edges per loop: {_sizes(np.sort(K)[::-1])}); "
              + fix)
    # Face components (= vertex components on a vertex-manifold mesh whose
    # vertices are all referenced) from the faces paired across interior
    # edges: faster than igl.vertex_components (docs/decisions.md).
    m = F.shape[0]
    f1, f2 = h1 % m, h2 % m
    ncomp, CF = connected_components(
        sp.csr_matrix((np.ones(f1.size, np.int8), (f1, f2)), shape=(m, m)), directed=False)
    if ncomp > 1:
        C = np.empty(n, np.int64)
        C[F.ravel()] = np.repeat(CF, 3)
        nv, nf = np.bincount(C), np.bincount(CF)
        order = np.argsort(-nf, kind="stable")
        _fail("components", ncomp, f"the mesh has {ncomp} connected components (faces: "
              f"{_sizes(nf[order])}; vertices: {_sizes(nv[order])}); map each one separately "
              "or keep the largest (labels from igl.facet_components or igl.vertex_components).")
    return E, uE, EMAP


def _inconsistent_edges(E, EMAP, ne):
    """Number of interior edges traversed twice in the same direction."""
    forward = np.bincount(EMAP, weights=E[:, 0] < E[:, 1], minlength=ne)
    return int(np.count_nonzero(forward != 1))


def orient(F, E, uE, EMAP, n, notes):
    """Repair mixed orientation, then reject non-orientable and genus > 0 meshes."""
    m, ne = F.shape[0], uE.shape[0]
    chi = n - ne + m  # V - E + F (igl.euler_characteristic needs libigl >= 2.6.3)
    bad = _inconsistent_edges(E, EMAP, ne)
    reoriented = 0
    if bad:
        FB = igl.bfs_orient(F)[0]
        flip = np.ones(m, bool)
        for s in range(3):
            flip &= ~(np.roll(F, s, axis=1) == FB).all(axis=1)
        if np.count_nonzero(flip) * 2 > m:  # keep the input's majority orientation
            flip = ~flip
        FF = np.where(flip[:, None], F[:, [0, 2, 1]], F)  # flip = swap the last two indices
        E2, _, EMAP2 = igl.unique_edge_map(FF)[:3]
        if _inconsistent_edges(E2, EMAP2, ne):
            _fail("non_orientable", 2 - chi, f"the mesh is non-orientable: no consistent face "
                  f"orientation exists (Euler characteristic V - E + F = {chi}, i.e. "
                  f"{plural(2 - chi, 'cross-cap')}: 1 a projective plane, 2 a Klein bottle); a "
                  "spherical map needs an orientable genus-0 surface: repair or remesh the input.")
        reoriented = int(np.count_nonzero(flip))
        F = FF
        notes.append(f"mixed orientation: {plural(bad, 'edge')} traversed twice in the same "
                     f"direction; flipped {plural(reoriented, 'face')} to orient consistently "
                     "(igl.bfs_orient)")
    if chi != 2:
        g = (2 - chi) // 2
        _fail("genus", g, f"the mesh has genus {g} (Euler characteristic V - E + F = {n} - {ne} + "
              f"{m} = {chi}, genus = (2 - chi) / 2); a spherical map needs genus 0: remove the "
              f"{plural(g, 'handle')} (topological repair) or remesh the surface as a sphere.")
    return F, reoriented


def quick_topology(F, n):
    """Unique edges of a valid mesh in one pass, or None when a full check is needed.

    For the common input (closed, manifold, connected, genus 0, consistently
    oriented, every vertex used) this replaces the checks of
    :func:`check_topology`, :func:`orient` and the duplicate-face sort with one
    pairing of the ``3m`` half-edges (scipy's COO -> CSR bucket sort): half-edge
    ``h`` goes to row ``min(i, j)``, column ``2 max(i, j) + (i < j)``, so on such
    a mesh every (row, column) occurs once and each edge's two halves sit side
    by side, in opposite directions.  A boundary, an edge in 3+ faces, a
    repeated directed half-edge (mixed orientation, a duplicate face) breaks
    that.  Vertex-manifoldness needs no fan count: split every non-manifold
    vertex into its fans and the result is a closed surface with the same edges
    and faces and more vertices, connected iff the faces are connected across
    edges; a connected closed surface has ``V - E + F <= 2``, so ``V - E + F = 2``
    with connected faces leaves no vertex with two fans.

    Parameters
    ----------
    F : (m, 3) int64 array
    n : int
        Number of vertices.

    Returns
    -------
    (e, 2) int64 array or None
        The unique edges ``(i, j)``, ``i < j``, or None (the caller then runs
        the full checks, which name the problem).
    """
    m = F.shape[0]
    if ((F[:, 0] == F[:, 1]) | (F[:, 1] == F[:, 2]) | (F[:, 2] == F[:, 0])).any():
        return None
    if n - m // 2 != 2 or m % 2 or np.bincount(F.ravel(), minlength=n).min() == 0:
        return None  # V - E + F = n - m / 2 on a closed edge-manifold mesh; unused vertices
    src = F[:, [1, 2, 0]].T.ravel()
    dst = F[:, [2, 0, 1]].T.ravel()
    lo, hi = np.minimum(src, dst), np.maximum(src, dst)
    A = sp.csr_matrix((np.arange(1, 3 * m + 1, dtype=np.float64), (lo, 2 * hi + (src < dst))),
                      shape=(n, 2 * n))
    A.sum_duplicates()
    c = A.indices
    if A.nnz != 3 * m or not (np.array_equal(c[0::2] >> 1, c[1::2] >> 1)
                              and not (c[0::2] & 1).any() and (c[1::2] & 1).all()):
        return None
    h1 = A.data[1::2].astype(np.int64) - 1
    h2 = A.data[0::2].astype(np.int64) - 1
    ncomp, _ = connected_components(
        sp.csr_matrix((np.ones(h1.size, np.int8), (h1 % m, h2 % m)), shape=(m, m)),
        directed=False)
    return np.column_stack([lo[h1], hi[h1]]) if ncomp == 1 else None

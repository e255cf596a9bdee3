"""Input validation: is (V, F) a closed, manifold, connected genus-0 triangle mesh?

See :func:`validate_mesh` for the checks (in order, each assuming the earlier
ones) and the automatic fixes.
"""

from dataclasses import dataclass, field

import igl
import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from .errors import MeshError
from .metrics import signed_image_volumes

ZERO_AREA_RTOL = 1e-12
"""A face is zero-area when its area is below this times the squared mean edge length."""
ZERO_VOLUME_RTOL = 1e-12
"""The enclosed volume is zero when ``|volume|`` is below this times ``area ** 1.5``."""


@dataclass
class ValidatedMesh:
    """A mesh that passed :func:`validate_mesh`, ready to map.

    Attributes
    ----------
    V : (k, 3) float64 array, C-contiguous
        Referenced vertices of the input, in input order.
    F : (m, 3) int64 array, C-contiguous
        Faces re-indexed into ``V``, consistently oriented outward.
    vertex_index : (k,) int64 array
        Row of the input ``V`` for each row of ``V``.
    unreferenced : (j,) int64 array
        Input rows used by no face (dropped).
    orientation_flipped : bool
        All faces were flipped because the input was (mostly) oriented inward.
    notes : list of str
        Human-readable record of every automatic fix and accepted oddity.
    faces_reoriented : int
        Faces flipped by the mixed-orientation repair (before any global flip).
    """

    V: np.ndarray
    F: np.ndarray
    vertex_index: np.ndarray
    unreferenced: np.ndarray
    orientation_flipped: bool = False
    notes: list = field(default_factory=list)
    faces_reoriented: int = 0


def _fail(problem, count, text):
    raise MeshError(problem, count, f"invalid mesh ({problem}): {text}")


def _n(k, one, many=None):
    return f"{k} {one if k == 1 else many or one + 's'}"


def _sizes(counts, limit=8):
    return ", ".join(str(int(c)) for c in counts[:limit]) + (", ..." if len(counts) > limit else "")


def _arrays(V, F, notes):
    """Parse ``V``, ``F`` to float64 / int64: empty, shape, dtype, index_range, non_finite."""
    try:
        V, F = np.asarray(V), np.asarray(F)
    except (ValueError, TypeError) as err:
        _fail("shape", 1, f"V and F must be rectangular arrays ({err}).")
    empty = [name for name, A in (("V", V), ("F", F)) if A.size == 0]
    if empty:
        _fail("empty", len(empty), f"{_n(len(empty), 'empty array')} ({' and '.join(empty)}; V "
              f"{V.shape}, F {F.shape}); a closed mesh needs at least 4 vertices and 4 faces.")
    bad = [f"{name} has shape {A.shape}" for name, A in (("V", V), ("F", F))
           if A.ndim != 2 or A.shape[1] != 3]
    if bad:
        _fail("shape", len(bad), f"{_n(len(bad), 'array')} with the wrong shape "
              f"({'; '.join(bad)}); V must be (n, 3) vertex positions and F (m, 3) triangles "
              "(triangulate polygons first, e.g. igl.polygons_to_triangles).")
    if V.dtype == bool or not (np.issubdtype(V.dtype, np.integer)
                               or np.issubdtype(V.dtype, np.floating)):
        _fail("dtype", V.size, f"V has dtype {V.dtype}; its {V.size} entries must be real numbers "
              "(e.g. V.astype(np.float64)).")
    if np.issubdtype(F.dtype, np.floating):
        frac = ~np.isfinite(F) | (F != np.round(F))
        k = int(np.count_nonzero(frac))
        if k:
            what = _n(k, "non-integer entry", "non-integer entries")
            _fail("dtype", k, f"F has dtype {F.dtype} with {what} (in "
                  f"{_n(np.count_nonzero(frac.any(axis=1)), 'face')}); "
                  "face indices must be integers (was the right array read as F?).")
        notes.append(f"F had dtype {F.dtype} with integral values; converted to int64")
    elif F.dtype == bool or not np.issubdtype(F.dtype, np.integer):
        _fail("dtype", F.size, f"F has dtype {F.dtype}; its {F.size} entries must be integer "
              "vertex indices (e.g. F.astype(np.int64)).")
    n = V.shape[0]
    out = (F < 0) | (F >= n)
    k = int(np.count_nonzero(out))
    if k:
        neg = int(np.count_nonzero(F < 0))
        _fail("index_range", k, f"{_n(k, 'index', 'indices')} of F outside 0..{n - 1} ({neg} "
              f"negative, {k - neg} >= n = {n}; in {_n(np.count_nonzero(out.any(axis=1)), 'face')}"
              "); indices are 0-based rows of V (OBJ files are 1-based: igl.read_triangle_mesh "
              "converts them).")
    V = np.array(V, dtype=np.float64, order="C")
    F = np.array(F, dtype=np.int64, order="C")
    bad = ~np.isfinite(V).all(axis=1)
    if bad.any():
        k = int(np.count_nonzero(bad))
        _fail("non_finite", k, f"{_n(k, 'vertex', 'vertices')} with NaN or infinite coordinates "
              f"(first: row {np.flatnonzero(bad)[0]}); fix them, or drop their faces and then "
              "the unreferenced vertices (igl.remove_unreferenced).")
    return V, F


def _faces(F):
    """Reject faces with a repeated index and faces on the same vertex set."""
    rep = (F[:, 0] == F[:, 1]) | (F[:, 1] == F[:, 2]) | (F[:, 2] == F[:, 0])
    if rep.any():
        k, f = int(np.count_nonzero(rep)), np.flatnonzero(rep)[0]
        _fail("degenerate_faces", k, f"{_n(k, 'face')} with a repeated vertex index (first: face "
              f"{f} = {F[f].tolist()}); drop those rows of F (then igl.remove_unreferenced), or "
              "repair with pymeshfix.MeshFix(V, F).repair().")
    if not _has_duplicate_rows(F):
        return
    _, IA, IC = igl.unique_simplices(F)
    k = F.shape[0] - IA.shape[0]
    if k:
        dup = np.ones(F.shape[0], bool)
        dup[IA] = False
        f = np.flatnonzero(dup)[0]
        _fail("duplicate_faces", k, f"{_n(k, 'face')} repeating the vertex set of another face "
              f"(either orientation; first: face {f} = face {IA[IC[f]]}); remove them with "
              "igl.resolve_duplicated_faces or igl.unique_simplices.")


def _has_duplicate_rows(F):
    """Whether two faces have the same vertex set (in any order).

    Sorts one int64 key per face: 5x faster than ``igl.unique_simplices`` on
    bimba's 50k faces, which :func:`_faces` then calls only to name the
    duplicates of a mesh that has some.
    """
    n = int(F.max()) + 1
    if n ** 3 >= 2 ** 63:  # the key would overflow
        return igl.unique_simplices(F)[1].shape[0] < F.shape[0]
    S = np.sort(F, axis=1)
    key = (S[:, 0] * n + S[:, 1]) * n + S[:, 2]
    key.sort()
    return bool((key[1:] == key[:-1]).any())


def _interior_half_edges(uEC, uEE):
    """The two half-edges ``h1, h2`` of each interior edge (valence 2), from the
    unique edge -> half-edge map ``uEC, uEE`` of ``igl.unique_edge_map``
    (half-edge ``h = f + m c`` is opposite corner ``(f, c)``)."""
    start = uEC[:-1][np.diff(uEC) == 2]
    return uEE[start], uEE[start + 1]


def _fans_per_vertex(F, h1, h2, n):
    """Number of face fans around each vertex of an edge-manifold mesh.

    A vertex is manifold when this is 1: the definition of ``igl.is_vertex_manifold``,
    computed 4x faster as the connected components of the graph joining the two
    corners at each end of every interior edge (half-edges ``h1, h2`` from
    :func:`_interior_half_edges`).
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


def _topology(F, n):
    """Edge- and vertex-manifold, closed, connected; returns E, uE, EMAP of igl.unique_edge_map."""
    E, uE, EMAP, uEC, uEE = igl.unique_edge_map(F)
    valence = np.diff(uEC)
    if (valence > 2).any():
        k, e = int(np.count_nonzero(valence > 2)), np.flatnonzero(valence > 2)[0]
        _fail("nonmanifold_edge", k, f"{_n(k, 'edge')} shared by more than 2 faces (first: edge "
              f"{uE[e].tolist()} in {valence[e]} faces); repair with "
              "pymeshfix.MeshFix(V, F).repair() or cut them apart with igl.split_nonmanifold.")
    h1, h2 = _interior_half_edges(uEC, uEE)
    fans = _fans_per_vertex(F, h1, h2, n)
    if (fans > 1).any():
        k, v = int(np.count_nonzero(fans > 1)), np.flatnonzero(fans > 1)[0]
        _fail("nonmanifold_vertex", k, f"{_n(k, 'non-manifold vertex', 'non-manifold vertices')}"
              f" whose faces form several fans, e.g. a bowtie (first: vertex {v}, {fans[v]} fans);"
              " split with igl.split_nonmanifold or repair with pymeshfix.MeshFix(V, F).repair().")
    be = uE[valence == 1]
    if be.size:  # each boundary vertex has 2 boundary edges: graph components = loops
        bv, inv = np.unique(be, return_inverse=True)
        inv = inv.reshape(-1, 2)
        A = sp.csc_matrix((np.ones(inv.size, np.int64), (inv.ravel(), inv[:, ::-1].ravel())),
                          shape=(bv.size, bv.size))
        nloops, _, K = igl.connected_components(A)
        _fail("boundary", be.shape[0], f"the mesh is open: {_n(be.shape[0], 'boundary edge')} in "
              f"{_n(nloops, 'boundary loop')} (edges per loop: {_sizes(np.sort(K)[::-1])}); close "
              "the holes, e.g. pymeshfix.MeshFix(V, F).repair() or a triangle fan per loop of "
              "igl.boundary_loop_all.")
    # Face components (= vertex components on a vertex-manifold mesh whose
    # vertices are all referenced) from the faces paired across interior
    # edges: 2x faster than igl.vertex_components on bimba.
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


def _orient(F, E, uE, EMAP, n, notes):
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
                  f"{_n(2 - chi, 'cross-cap')}, e.g. a Klein bottle); a spherical map needs an "
                  "orientable genus-0 surface: repair or remesh the input.")
        reoriented = int(np.count_nonzero(flip))
        F = FF
        notes.append(f"mixed orientation: {_n(bad, 'edge')} traversed twice in the same direction;"
                     f" flipped {_n(reoriented, 'face')} to orient consistently (igl.bfs_orient)")
    if chi != 2:
        g = (2 - chi) // 2
        _fail("genus", g, f"the mesh has genus {g} (Euler characteristic V - E + F = {n} - {ne} + "
              f"{m} = {chi}, genus = (2 - chi) / 2); a spherical map needs genus 0: remove the "
              f"{_n(g, 'handle')} (topological repair) or remesh the surface as a sphere.")
    return F, reoriented


def _geometry(V, F, uE, notes):
    """Reject zero-length edges, zero-area faces and zero volume; returns the signed volume."""
    _, SVI, SVJ = igl.remove_duplicate_vertices(V, 0.0)
    if SVI.shape[0] < V.shape[0]:
        same = SVJ[uE[:, 0]] == SVJ[uE[:, 1]]  # an edge of zero length joins two of them
        if same.any():
            k, e = int(np.count_nonzero(same)), uE[np.flatnonzero(same)[0]]
            _fail("zero_length_edge", k, f"{_n(k, 'edge')} of zero length, whose two vertices "
                  f"share a position (first: edge {e.tolist()}); merge them with "
                  "igl.remove_duplicate_vertices(V, F, 0.0), then drop the faces with a repeated "
                  "index and run igl.remove_unreferenced.")
        count = np.bincount(SVJ)
        k, p = int(np.count_nonzero(count[SVJ] > 1)), int(np.count_nonzero(count > 1))
        notes.append(f"{k} vertices share {_n(p, 'position')} with vertices not joined to them by "
                     "an edge; accepted (the map depends on edge lengths only)")
    X = V - 0.5 * (V.min(axis=0) + V.max(axis=0))  # centered: less rounding in areas and volume
    D = X[uE[:, 0]] - X[uE[:, 1]]
    lbar = np.sqrt(np.einsum("ij,ij->i", D, D)).mean()
    area = 0.5 * igl.doublearea(X, F)
    small = area < ZERO_AREA_RTOL * lbar ** 2
    if small.any():
        k = int(np.count_nonzero(small))
        _fail("zero_area", k, f"{_n(k, 'face')} of zero area (below {ZERO_AREA_RTOL:g} x the "
              f"squared mean edge length; first: face {np.flatnonzero(small)[0]}); remove them "
              "with pymeshfix.MeshFix(V, F).repair() or remesh.")
    vol = float(signed_image_volumes(F, X).sum()) / 6.0  # sum of det[X_i, X_j, X_k] / 6
    if abs(vol) <= ZERO_VOLUME_RTOL * area.sum() ** 1.5:
        _fail("orientation", F.shape[0], f"cannot orient the {F.shape[0]} faces outward: the mesh "
              f"encloses zero signed volume ({vol:.3g}), e.g. a flat double-sided sheet; the input "
              "must bound a solid.")
    return vol


def validate_mesh(V, F):
    """Check and prepare a mesh for the spherical conformal map.

    Parameters
    ----------
    V : (n, 3) array_like of real numbers
        Vertex positions (any real dtype; converted to float64).
    F : (m, 3) array_like of int
        Triangles, 0-based rows of ``V`` (any integer dtype, or floats with integral values).

    Returns
    -------
    ValidatedMesh
        ``V`` (float64) holds the referenced vertices in input order, ``F`` (int64)
        is re-indexed into it and oriented consistently and outward (positive total
        signed volume ``sum det[Vi, Vj, Vk] / 6``).  Automatic fixes, each recorded in
        ``notes``: unreferenced vertices are dropped; mixed orientation is repaired
        with ``igl.bfs_orient`` keeping the input's majority orientation; an inward
        mesh has all faces flipped (``orientation_flipped``).  Flipping a face swaps
        its last two indices.  Vertices at one position that share no edge are
        accepted with a note.

    Raises
    ------
    MeshError
        ``problem`` / ``count``, in the order checked: ``"empty"`` / arrays,
        ``"shape"`` / arrays, ``"dtype"`` / entries, ``"index_range"`` / entries,
        ``"non_finite"`` / vertices, ``"degenerate_faces"`` (repeated index) /
        faces, ``"duplicate_faces"`` / faces beyond the first on a vertex set,
        ``"nonmanifold_edge"`` (in > 2 faces) / edges, ``"nonmanifold_vertex"`` /
        vertices, ``"boundary"`` / boundary edges (the message gives the loops),
        ``"components"`` / components, ``"non_orientable"`` / cross-caps
        ``2 - chi``, ``"genus"`` / genus ``(2 - chi) / 2``, ``"zero_length_edge"`` /
        edges, ``"zero_area"`` (area < :data:`ZERO_AREA_RTOL` times the squared
        mean edge length) / faces, ``"orientation"`` (zero enclosed volume) / faces.
    """
    notes = []
    V, F = _arrays(V, F, notes)
    _faces(F)
    used = np.zeros(V.shape[0], bool)
    used[F.ravel()] = True
    vertex_index, unreferenced = np.arange(V.shape[0]), np.zeros(0, np.int64)
    if not used.all():
        V, F, _, vertex_index = igl.remove_unreferenced(V, F)
        unreferenced = np.flatnonzero(~used)
        k = unreferenced.size
        notes.append(f"dropped {_n(k, 'unreferenced vertex', 'unreferenced vertices')} (used by "
                     "no face)")
    E, uE, EMAP = _topology(F, V.shape[0])
    F, reoriented = _orient(F, E, uE, EMAP, V.shape[0], notes)
    flipped = bool(_geometry(V, F, uE, notes) < 0)
    if flipped:
        F = F[:, [0, 2, 1]]
        notes.append("the faces were oriented inward (negative signed volume); flipped all faces")
    return ValidatedMesh(V=np.ascontiguousarray(V, dtype=np.float64),
                         F=np.ascontiguousarray(F, dtype=np.int64),
                         vertex_index=np.asarray(vertex_index, dtype=np.int64),
                         unreferenced=unreferenced, orientation_flipped=flipped, notes=notes,
                         faces_reoriented=reoriented)

"""Input validation: is (V, F) a closed, manifold, connected genus-0 triangle mesh?

See :func:`validate_mesh` for the checks (in order, each assuming the earlier
ones) and the automatic fixes.
"""

from dataclasses import dataclass, field

import igl
import numpy as np

from ..errors import MeshError, plural
from .operators import signed_volumes
from .topology import check_topology, orient, quick_topology


def _fail(problem, count, text):
    raise MeshError.invalid(problem, count, text)

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
        Referenced vertices of the input, in input order, times ``scale``.
    F : (m, 3) int64 array, C-contiguous
        Faces re-indexed into ``V``, consistently oriented outward.
    vertex_index : (k,) int64 array
        Row of the input ``V`` for each row of ``V``.
    unreferenced : (j,) int64 array
        Input rows used by no face (dropped).
    nearest : (j,) int64 array
        For each unreferenced input row, the row of ``V`` nearest to it.
    n_input : int
        Rows of the input ``V``.
    scale : float
        The power of two the input coordinates were multiplied by (exactly, so
        that every derived quantity is the input's, scaled) to bring the
        bounding-box diagonal into [1, 2): coordinates near 1e-200 or 1e200 would
        otherwise under- or overflow in areas and cotangents.  The map does not
        depend on the scale of the input.
    orientation_flipped : bool
        All faces were flipped because the input was (mostly) oriented inward.
    notes : list of str
        Human-readable record of every automatic fix and accepted oddity.
    faces_reoriented : int
        Faces flipped by the mixed-orientation repair (before any global flip).
    repairs : list of str
        The notes that record a change to the input (``F``'s dtype converted,
        unreferenced vertices dropped, faces flipped), not an oddity accepted as it is;
        a map's result repeats them in its ``notes``.
    """

    V: np.ndarray = field(repr=False)
    F: np.ndarray = field(repr=False)
    vertex_index: np.ndarray = field(repr=False)
    unreferenced: np.ndarray = field(repr=False)
    nearest: np.ndarray = field(default=None, repr=False)
    n_input: int = None
    scale: float = 1.0
    orientation_flipped: bool = False
    notes: list = field(default_factory=list)
    faces_reoriented: int = 0
    repairs: list = field(default_factory=list)

    @property
    def faces_flipped(self):
        """Rows of ``F_input`` whose corners are in the opposite order to the input's (int)."""
        m = self.F.shape[0]
        return m - self.faces_reoriented if self.orientation_flipped else self.faces_reoriented

    @property
    def reorientation(self):
        """``"F re-oriented: 270 of 1886 faces flipped"`` (or ``"all 1886 faces"`` for an
        inward mesh), or None when ``F_input`` keeps every face of the input as it was: the
        faces a map of this mesh must be used with differ from the input's (str or None)."""
        k, m = self.faces_flipped, self.F.shape[0]
        if not k:
            return None
        if k == m:
            return f"F re-oriented: all {m} faces flipped (the input was oriented inward)"
        return f"F re-oriented: {k} of {plural(m, 'face')} flipped"

    @property
    def F_input(self):
        """(m, 3) int64: ``F`` in the input's vertex numbering (outward oriented)."""
        return self.vertex_index[self.F]

    def to_input(self, U):
        """Per-vertex rows of ``V``'s order in the input's order.

        Parameters
        ----------
        U : (k, ...) array
            One row per row of ``V`` (e.g. a map).

        Returns
        -------
        (n_input, ...) array
            ``U`` itself when no row was dropped; otherwise a new array in which
            each unreferenced input row gets the row of its nearest referenced vertex.
        """
        if self.unreferenced.size == 0:
            return U
        out = np.empty((self.n_input,) + U.shape[1:], dtype=U.dtype)
        out[self.vertex_index] = U
        out[self.unreferenced] = U[self.nearest]
        return out

    def from_input(self, X):
        """Rows of an input-ordered (n_input, ...) array for the rows of ``V``."""
        X = np.asarray(X)
        return X if self.unreferenced.size == 0 else X[self.vertex_index]


def _arrays(V, F, notes):
    """Parse ``V``, ``F`` to float64 / int64: empty, shape, dtype, index_range, non_finite."""
    try:
        V, F = np.asarray(V), np.asarray(F)
    except (ValueError, TypeError) as err:
        _fail("shape", 1, f"V and F must be rectangular arrays ({err}).")
    empty = [name for name, A in (("V", V), ("F", F)) if A.size == 0]
    if empty:
        _fail("empty", len(empty), f"{plural(len(empty), 'empty array')} ({' and '.join(empty)}; V "
              f"{V.shape}, F {F.shape}); a closed mesh needs at least 4 vertices and 4 faces.")
    bad = [f"{name} has shape {A.shape}" for name, A in (("V", V), ("F", F))
           if A.ndim != 2 or A.shape[1] != 3]
    if bad:
        _fail("shape", len(bad), f"{plural(len(bad), 'array')} with the wrong shape "
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
            what = plural(k, "non-integer entry", "non-integer entries")
            _fail("dtype", k, f"F has dtype {F.dtype} with {what} (in "
                  f"{plural(np.count_nonzero(frac.any(axis=1)), 'face')}); "
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
        _fail("index_range", k, f"{plural(k, 'index', 'indices')} of F outside 0..{n - 1} ({neg} "
              f"negative, {k - neg} >= n = {n}; in "
              f"{plural(np.count_nonzero(out.any(axis=1)), 'face')}); indices are 0-based rows "
              "of V (OBJ files are 1-based: igl.read_triangle_mesh converts them).")
    V = np.array(V, dtype=np.float64, order="C")
    F = np.array(F, dtype=np.int64, order="C")
    bad = ~np.isfinite(V).all(axis=1)
    if bad.any():
        k = int(np.count_nonzero(bad))
        _fail("non_finite", k,
              f"{plural(k, 'vertex', 'vertices')} with NaN or infinite coordinates "
              f"(first: row {np.flatnonzero(bad)[0]}); fix them, or drop their faces and then "
              "the unreferenced vertices (igl.remove_unreferenced).")
    return V, F


def _faces(F):
    """Reject faces with a repeated index and faces on the same vertex set."""
    rep = (F[:, 0] == F[:, 1]) | (F[:, 1] == F[:, 2]) | (F[:, 2] == F[:, 0])
    if rep.any():
        k, f = int(np.count_nonzero(rep)), np.flatnonzero(rep)[0]
        _fail("degenerate_faces", k,
              f"{plural(k, 'face')} with a repeated vertex index (first: face "
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
        _fail("duplicate_faces", k, f"{plural(k, 'face')} repeating the vertex set of another face "
              f"(either orientation; first: face {f} = face {IA[IC[f]]}); remove them with "
              "igl.resolve_duplicated_faces or igl.unique_simplices.")


def _has_duplicate_rows(F):
    """Whether two faces have the same vertex set (in any order).

    Sorts one int64 key per face, cheaper than ``igl.unique_simplices``
    (``docs/decisions.md``), which :func:`_faces` then calls only to name the
    duplicates of a mesh that has some.
    """
    n = int(F.max()) + 1
    if n ** 3 >= 2 ** 63:  # the key would overflow
        return igl.unique_simplices(F)[1].shape[0] < F.shape[0]
    S = np.sort(F, axis=1)
    key = (S[:, 0] * n + S[:, 1]) * n + S[:, 2]
    key.sort()
    return bool((key[1:] == key[:-1]).any())


def _positions(V):
    """``(SVJ, shared)``: the label of each vertex's position ((n,) int, equal labels for
    equal coordinates, ``igl.remove_duplicate_vertices`` with tolerance 0) and whether another
    vertex shares it ((n,) bool)."""
    _, _, SVJ = igl.remove_duplicate_vertices(V, 0.0)
    SVJ = np.asarray(SVJ).ravel()
    return SVJ, np.bincount(SVJ)[SVJ] > 1


def _geometry(V, F, uE, notes):
    """Reject zero-length edges, zero-area faces and zero volume; returns the signed volume."""
    SVJ, shared = _positions(V)
    if shared.any():
        same = SVJ[uE[:, 0]] == SVJ[uE[:, 1]]  # an edge of zero length joins two of them
        if same.any():
            k, e = int(np.count_nonzero(same)), uE[np.flatnonzero(same)[0]]
            _fail("zero_length_edge", k, f"{plural(k, 'edge')} of zero length, whose two vertices "
                  f"share a position (first: edge {e.tolist()}); merge them with "
                  "igl.remove_duplicate_vertices(V, F, 0.0), then drop the faces with a repeated "
                  "index and run igl.remove_unreferenced.")
        k, p = int(np.count_nonzero(shared)), int(np.count_nonzero(np.bincount(SVJ) > 1))
        notes.append(f"{k} vertices share {plural(p, 'position')} with vertices not joined to "
                     "them by an edge; accepted (the map depends on edge lengths only)")
    X = V - 0.5 * (V.min(axis=0) + V.max(axis=0))  # centered: less rounding in areas and volume
    D = X[uE[:, 0]] - X[uE[:, 1]]
    lbar = np.sqrt(np.einsum("ij,ij->i", D, D)).mean()
    area = 0.5 * igl.doublearea(X, F)
    small = area < ZERO_AREA_RTOL * lbar ** 2
    if small.any():
        k = int(np.count_nonzero(small))
        _fail("zero_area", k, f"{plural(k, 'face')} of zero area (below {ZERO_AREA_RTOL:g} x the "
              f"squared mean edge length; first: face {np.flatnonzero(small)[0]}); remove them "
              "with pymeshfix.MeshFix(V, F).repair() or remesh.")
    vol = float(signed_volumes(F, X).sum()) / 6.0  # sum of det[X_i, X_j, X_k] / 6
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
        accepted with a note.  ``repairs`` lists the notes of the fixes, which a map's
        result repeats in its ``notes``.

    Raises
    ------
    MeshError
        ``problem`` / ``count``, in the order checked: ``"empty"`` / arrays,
        ``"shape"`` / arrays, ``"dtype"`` / entries, ``"index_range"`` / entries,
        ``"non_finite"`` / vertices, ``"degenerate_faces"`` (repeated index) /
        faces, ``"duplicate_faces"`` / faces beyond the first on a vertex set,
        ``"nonmanifold_edge"`` (in > 2 faces) / edges, ``"nonmanifold_vertex"`` /
        vertices, ``"boundary"`` / boundary edges (the message gives the loops, and
        says to merge vertices where most boundary vertices share a position),
        ``"components"`` / components, ``"non_orientable"`` / cross-caps
        ``2 - chi``, ``"genus"`` / genus ``(2 - chi) / 2``, ``"zero_length_edge"`` /
        edges, ``"zero_area"`` (area < :data:`ZERO_AREA_RTOL` times the squared
        mean edge length) / faces, ``"orientation"`` (zero enclosed volume) / faces.
    """
    notes = []
    V, F = _arrays(V, F, notes)
    n_input = V.shape[0]
    uE = None if notes else quick_topology(F, n_input)
    if uE is None:  # the full checks: they name every problem, and repair what they can
        V, F, uE, index, reoriented, scale = _topology_in_full(V, F, notes)
    else:  # closed, manifold, connected, genus 0, consistently oriented, all vertices used
        index, reoriented = (np.arange(n_input), np.zeros(0, np.int64), np.zeros(0, np.int64)), 0
        V, scale = power_of_two_scaled(V, np.ones(n_input, bool))
    repairs = list(notes)  # _geometry's note is an accepted oddity, not a change
    flipped = bool(_geometry(V, F, uE, notes) < 0)
    if flipped:
        F = F[:, [0, 2, 1]]
        notes.append("the faces were oriented inward (negative signed volume); flipped all faces")
        repairs.append(notes[-1])
    vertex_index, unreferenced, nearest = index
    return ValidatedMesh(V=np.ascontiguousarray(V, dtype=np.float64),
                         F=np.ascontiguousarray(F, dtype=np.int64),
                         vertex_index=np.asarray(vertex_index, dtype=np.int64),
                         unreferenced=unreferenced, nearest=nearest, n_input=n_input,
                         scale=scale, orientation_flipped=flipped, notes=notes,
                         faces_reoriented=reoriented, repairs=repairs)


def _topology_in_full(V, F, notes):
    """Faces, unreferenced vertices, topology and orientation, each check naming its problem.

    Returns the scaled referenced vertices, the re-indexed consistently oriented
    faces, their unique edges, ``(vertex_index, unreferenced, nearest)``, the count
    of reoriented faces and the scale.
    """
    _faces(F)
    n_input = V.shape[0]
    used = np.zeros(n_input, bool)
    used[F.ravel()] = True
    vertex_index, unreferenced = np.arange(n_input), np.zeros(0, np.int64)
    nearest = np.zeros(0, np.int64)
    V, scale = power_of_two_scaled(V, used)
    if not used.all():
        V_all = V
        V, F, _, vertex_index = igl.remove_unreferenced(V, F)
        unreferenced = np.flatnonzero(~used)
        from scipy.spatial import cKDTree  # scipy.spatial only for unreferenced vertices

        nearest = cKDTree(V).query(V_all[unreferenced])[1].astype(np.int64)
        k = unreferenced.size
        notes.append(f"dropped {plural(k, 'unreferenced vertex', 'unreferenced vertices')} "
                     "(used by no face); in maps each gets the image of its nearest surface vertex")
    E, uE, EMAP = check_topology(F, V.shape[0], shared=lambda: _positions(V)[1])
    F, reoriented = orient(F, E, uE, EMAP, V.shape[0], notes)
    return V, F, uE, (vertex_index, unreferenced, nearest), reoriented, scale


def power_of_two_scaled(V, used):
    """``V * 2**e`` (exact) with the referenced vertices' bounding-box diagonal in [1, 2).

    Two exact steps: first the largest coordinate into [0.5, 1) (so the diagonal
    can neither overflow nor underflow), then the diagonal into [1, 2).
    """
    W = V[used]
    largest = float(np.abs(W).max())
    if largest == 0.0:
        return V, 1.0  # every referenced vertex at the origin: zero-length edges, reported later
    e = -int(np.frexp(largest)[1])
    W = np.ldexp(W, e)
    diag = float(np.linalg.norm(W.max(axis=0) - W.min(axis=0)))
    if diag > 0.0:
        e += 1 - int(np.frexp(diag)[1])
    if e == 0:
        return V, 1.0
    return np.ldexp(V, e), float(np.ldexp(1.0, e))

"""Read a PLY triangle mesh with the ``plyfile`` package: libigl's PLY reader aborts on some files."""

import numpy as np

from .check_obj import TextMesh, fan_triangles

#: Names of the face element's list of vertex indices, as PLY writers spell it.
FACE_LISTS = ("vertex_indices", "vertex_index")


def read_ply(path):
    """Read an ASCII or binary PLY file's vertices and faces with ``plyfile``.

    libigl's PLY reader (2.6.3) aborts the Python process (``free(): double free``) on a
    face list whose lengths vary (a mesh of triangles and quads) and on an ASCII file cut
    anywhere, and reads a cut binary file as faces of index 0 or of no vertex.  So PLY
    files are read here with ``plyfile``, which reports what it could not read.

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    TextMesh
        ``V`` (n, 3) float64 from the ``vertex`` element's ``x``, ``y``, ``z``; ``F``
        (m, 3) int64, the ``face`` element's index lists with polygons split into fans
        ``(i0, ij, ij+1)`` (as :func:`igl_spheremap.io.check_obj` does); ``polygons``,
        the number of faces with more than 3 vertices.

    Raises
    ------
    ValueError
        ``plyfile`` cannot parse the file (a cut file, a bad header: its message), it has
        no ``vertex`` element with ``x``, ``y``, ``z`` or no ``face`` element with a list of
        vertex indices (:data:`FACE_LISTS`), or faces with fewer than 3 vertices (their
        count and the first).  Indices out of range and non-finite coordinates are
        counted by :func:`igl_spheremap.io.read_mesh`'s own checks.
    """
    from plyfile import PlyData

    try:
        ply = PlyData.read(str(path))
    except Exception as exc:  # plyfile raises its own parse errors, struct's and numpy's
        raise ValueError(f"cannot read '{path}' as PLY: {exc}") from None
    names = {element.name: element for element in ply.elements}
    vertex, face = names.get("vertex"), names.get("face")
    coords = () if vertex is None else [p.name for p in vertex.properties]
    if not {"x", "y", "z"} <= set(coords):
        raise ValueError(f"'{path}' is not a PLY mesh: no 'vertex' element with x, y, z "
                         f"(elements: {', '.join(names) or 'none'})")
    lists = [p.name for p in (face.properties if face is not None else ()) if p.name in FACE_LISTS]
    if not lists:
        raise ValueError(f"'{path}' is not a PLY mesh: no 'face' element with a list "
                         f"'vertex_indices' (elements: {', '.join(names)})")
    V = np.column_stack([np.asarray(vertex[c], dtype=np.float64) for c in "xyz"])
    faces = face[lists[0]]
    counts = np.fromiter((len(f) for f in faces), dtype=np.int64, count=len(faces))
    short = np.flatnonzero(counts < 3)
    if short.size:
        raise ValueError(f"'{path}' is not a PLY triangle mesh: faces with fewer than 3 "
                         f"vertices: {short.size} (first: face {short[0]}, "
                         f"{np.asarray(faces[short[0]]).tolist()})")
    index = np.concatenate([np.asarray(f, dtype=np.int64) for f in faces]) if len(faces) \
        else np.zeros(0, dtype=np.int64)
    return TextMesh(V, fan_triangles(index, counts), int(np.count_nonzero(counts > 3)))

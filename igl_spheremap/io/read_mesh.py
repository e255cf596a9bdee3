"""Read a triangle mesh from a libigl, GIfTI or FreeSurfer file, saying what is wrong with it."""

import warnings
from pathlib import Path

import numpy as np

from ..errors import plural
from .check_mesh import check_mesh
from .check_obj import check_obj
from .check_off import check_off
from .check_stl import check_stl
from .check_wrl import check_wrl
from .mesh_format import curv_layout, mesh_format
from .read_msh import read_msh
from .read_ply import read_ply

#: Strict parses whose result libigl's reading must equal.
_CHECKS = {".obj": check_obj, ".off": check_off, ".stl": check_stl, ".wrl": check_wrl,
           ".mesh": check_mesh}

#: Formats read without libigl, whose readers abort (PLY) or hang (Gmsh) on some files.
_READERS = {".ply": read_ply, ".msh": read_msh}


def read_mesh(path, *, return_metadata=False):
    """Read a triangle mesh; the reader is chosen by :func:`mesh_format`.

    * ``"mesh"`` (``.obj .off .ply .stl .wrl .mesh .msh``): ``igl.read_triangle_mesh``
      (MEDIT ``.mesh``: ``igl.readMESH``'s triangles; ``read_triangle_mesh`` returns the
      boundary of the tetrahedra, none for a surface).  OBJ, OFF, ASCII STL, VRML and
      MEDIT files are first parsed strictly by :func:`check_obj` / :func:`check_off` /
      :func:`check_stl` / :func:`check_wrl` / :func:`check_mesh` (libigl misreads,
      crashes or hangs on some bad content) and libigl's result must equal that
      parse.  PLY files are read by :func:`read_ply` (``plyfile``) and Gmsh files by
      :func:`read_msh` (``meshio``), not by libigl, whose readers abort the process on
      some PLY files and never return on some damaged Gmsh files.  Polygons are split
      into fans ``(i0, ij, ij+1)``, as libigl does; their number is in the metadata.
      STL stores every triangle with its own corners, so coincident corners are
      merged with ``igl.remove_duplicate_vertices`` (exact matches only).
    * ``"gifti"`` (``.gii``, ``.surf.gii``): ``nibabel.load``; vertices from the
      ``NIFTI_INTENT_POINTSET`` array and faces from the ``NIFTI_INTENT_TRIANGLE``
      array.
    * ``"freesurfer"`` (``lh.white``, ``rh.pial``, ``lh.sphere``... any file
      with a FreeSurfer magic number): ``nibabel.freesurfer.read_geometry``
      (quad files are split into triangles by nibabel).

    Whatever the format, the vertices must be finite and the face indices in
    range.  libigl prints its own diagnostics on stderr; the exceptions raised
    here do not depend on them.

    Parameters
    ----------
    path : str or os.PathLike
    return_metadata : bool, default False
        Also return a dict of format metadata: ``volume_info`` (FreeSurfer
        volume geometry, an ``OrderedDict``), ``gifti_meta`` (the GIfTI
        pointset array's metadata, a dict), ``polygons`` (OBJ/OFF/PLY: number of
        faces with more than 3 vertices, split into triangles).

    Returns
    -------
    V : (n, 3) float64 array
        Vertex positions, in the file's units (FreeSurfer/GIfTI: millimetres,
        usually stored as float32 in the file).
    F : (m, 3) int64 array
        Triangles, 0-based vertex indices.
    family : str
        ``"mesh"``, ``"gifti"`` or ``"freesurfer"``.
    metadata : dict
        Only when ``return_metadata``.

    Raises
    ------
    FileNotFoundError
        ``path`` does not exist.
    IsADirectoryError, PermissionError
        ``path`` is a folder or cannot be opened.
    ValueError
        The file is empty, is a FreeSurfer curv (per-vertex data) file, its format
        cannot be told from the name or content,
        it cannot be parsed (for OBJ/OFF/STL/VRML/MEDIT: the problems with their
        counts and first lines, see :func:`check_obj` ...), it holds no
        triangles, has non-finite coordinates or face indices out of range.
    """
    path = Path(path)
    family = mesh_format(path)
    layout = curv_layout(path) if family is None else None
    if layout is not None:
        n, k = layout
        raise ValueError(f"'{path}' is a FreeSurfer per-vertex data file (curv format: "
                         f"{plural(n, 'value')}{'' if k == 1 else f' x {k}'}), not a surface; pass "
                         "it as data (--data, --features) and the surface itself (lh.white, ...) "
                         "as the mesh")
    if family is None:
        raise ValueError(f"cannot tell the mesh format of '{path}': expected one of "
                         ".obj .off .ply .stl .wrl .mesh .msh, .gii/.surf.gii (or .gii.gz), or a "
                         "FreeSurfer surface (lh.white, rh.pial, ...)")
    with open(path, "rb") as fh:  # PermissionError here, before any reader
        if not fh.read(1):
            raise ValueError(f"'{path}' is empty (0 bytes)")
    meta = {}
    if family == "mesh":
        V, F, meta["polygons"] = _read_igl(path)
    elif family == "gifti":
        V, F, meta["gifti_meta"] = _read_gifti(path)
    else:
        V, F, meta["volume_info"] = _read_freesurfer(path)
    V, F = check_arrays(path, V, F)
    if return_metadata:
        return V, F, family, meta
    return V, F, family


def check_arrays(path, V, F):
    """``(V, F)`` as float64 / int64 arrays after checking shapes, finiteness and index range.

    Parameters
    ----------
    path : str or os.PathLike
        Named in messages.
    V : (n, 3) array
    F : (m, 3) integer array

    Returns
    -------
    V : (n, 3) float64 array
    F : (m, 3) int64 array

    Raises
    ------
    ValueError
        No vertices or faces, shapes other than ``(n, 3)`` / ``(m, 3)``,
        vertices with non-finite coordinates, or face indices outside
        ``[0, n)`` (counts and first offender in the message).
    """
    V = np.ascontiguousarray(V, dtype=np.float64)
    F = np.ascontiguousarray(F, dtype=np.int64)
    if F.size == 0 or V.size == 0:
        raise ValueError(f"'{path}' holds no triangles (read "
                         f"{plural(len(V), 'vertex', 'vertices')}, {plural(len(F), 'face')})")
    if V.ndim != 2 or V.shape[1] != 3 or F.ndim != 2 or F.shape[1] != 3:
        raise ValueError(f"'{path}' is not a 3-D triangle mesh: V {V.shape}, F {F.shape}")
    bad_v = np.flatnonzero(~np.isfinite(V).all(axis=1))
    bad_f = np.flatnonzero(((F < 0) | (F >= len(V))).any(axis=1))
    problems = []
    if len(bad_v):
        problems.append(f"{plural(len(bad_v), 'vertex', 'vertices')} with non-finite coordinates "
                        f"(first: vertex {bad_v[0]}, {V[bad_v[0]].tolist()})")
    if len(bad_f):
        problems.append(f"{plural(len(bad_f), 'face')} with vertex indices outside 0..{len(V) - 1} "
                        f"(first: face {bad_f[0]}, {F[bad_f[0]].tolist()})")
    if problems:
        raise ValueError(f"'{path}': " + "; ".join(problems))
    return V, F


def _read_igl(path):
    import igl

    if path.suffix.lower() in _READERS:
        parsed = _READERS[path.suffix.lower()](path)
        return parsed.V, parsed.F, parsed.polygons
    check = _CHECKS.get(path.suffix.lower())
    parsed = check(path) if check else None
    try:
        if path.suffix.lower() == ".mesh":  # read_triangle_mesh gives the tetrahedra's boundary
            V, _, F = igl.readMESH(str(path))
        else:
            V, F = igl.read_triangle_mesh(str(path))
    except RuntimeError as exc:
        raise ValueError(f"cannot read '{path}': libigl's {path.suffix.lower()} reader failed "
                         f"({exc})") from None
    if parsed is not None and not (np.array_equal(V, parsed.V) and np.array_equal(F, parsed.F)):
        raise ValueError(f"libigl read '{path}' as {plural(V.shape[0], 'vertex', 'vertices')} and "
                         f"{plural(F.shape[0], 'triangle')}, a strict parse as "
                         f"{parsed.V.shape[0]} and {parsed.F.shape[0]} (or other values): the file "
                         "has content that readers disagree on")
    if path.suffix.lower() == ".stl" and F.size:
        V, _, _, F = igl.remove_duplicate_vertices(V, F, 0.0)
    return V, F, 0 if parsed is None else parsed.polygons


def _read_gifti(path):
    import nibabel as nib

    try:
        img = nib.load(str(path))
    except Exception as exc:  # nibabel raises several types for corrupt XML
        raise ValueError(f"cannot read GIfTI '{path}': {exc}") from None
    points = img.get_arrays_from_intent("NIFTI_INTENT_POINTSET")
    tris = img.get_arrays_from_intent("NIFTI_INTENT_TRIANGLE")
    if len(points) != 1 or len(tris) != 1:
        raise ValueError(f"'{path}' is not a GIfTI surface: it has "
                         f"{plural(len(points), 'POINTSET array')} and "
                         f"{plural(len(tris), 'TRIANGLE array')} (need one of each)")
    return points[0].data, tris[0].data, dict(points[0].meta)


def _read_freesurfer(path):
    import nibabel.freesurfer as fs

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # "No volume information contained in the file"
            V, F, volume_info = fs.read_geometry(str(path), read_metadata=True)
    except Exception as exc:
        raise ValueError(f"cannot read FreeSurfer surface '{path}': {exc}") from None
    return V, F, volume_info

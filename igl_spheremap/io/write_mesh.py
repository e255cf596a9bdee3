"""Write a triangle mesh as a libigl, GIfTI or FreeSurfer file, atomically, at full precision
where the format allows it."""

from pathlib import Path

import numpy as np

from ..errors import plural
from ..mesh.arrays import as_faces
from .atomic import atomic_path
from .write_formats import write_obj, write_off, write_ply
from .mesh_format import mesh_format

#: Coordinate precision each output stores: what ``precision=None`` means.
STORED_PRECISION = {".obj": "float64", ".off": "float64", ".ply": "float64", ".stl": "float32",
                    "gifti": "float32", "freesurfer": "float32"}
_OWN_WRITERS = {".obj": write_obj, ".off": write_off, ".ply": write_ply}


def write_mesh(path, V, F, *, family=None, metadata=None, precision=None):
    """Write ``(V, F)`` to ``path``; the file appears under its name only when complete.

    What each format stores (the rounding that :func:`stored_folds` sees):

    * ``.obj``, ``.off``: text, every coordinate as the shortest decimal that
      reads back to the same float64 (exact round trip; written here, since
      libigl writes 15 significant digits).
    * ``.ply``: binary little-endian, float64 ``x y z`` and ``int32`` index
      lists (exact; written with ``plyfile``, since libigl writes ASCII with 6
      digits).
    * ``.stl``: binary STL by ``igl.writeSTL``: float32 corners, every
      triangle with its own three corners, so the per-vertex correspondence is
      lost (see :func:`check_sphere_output`).
    * ``.wrl``: libigl's VRML writer (about 15 significant digits, not exact).
    * ``"gifti"`` (``.surf.gii``): a ``NIFTI_INTENT_POINTSET`` array and an
      ``int32`` ``NIFTI_INTENT_TRIANGLE`` array, written by nibabel.  Float32
      by default, the only float type of the GIfTI 1.0 standard (section
      2.3.4.2: UINT8, INT32, FLOAT32).  ``precision="float64"`` writes a
      ``NIFTI_TYPE_FLOAT64`` pointset, outside the standard: nibabel reads it
      back exactly, but other tools (e.g. Connectome Workbench) may refuse it.
    * ``"freesurfer"``: a FreeSurfer triangle surface by
      ``nibabel.freesurfer.write_geometry``: big-endian float32 coordinates
      and int32 indices, float32 being fixed by the format.

    Parameters
    ----------
    path : str or os.PathLike
        Destination; its folder must exist.
    V : (n, 3) float array
        Finite coordinates.
    F : (m, 3) int array
        0-based vertex indices.
    family : {"mesh", "gifti", "freesurfer"}, optional
        Default: :func:`igl_spheremap.io.mesh_format` of ``path``.
    metadata : dict, optional
        ``"gifti_triangle_meta"``: metadata for the GIfTI triangle array (e.g.
        ``TopologicalType``); ``"gifti_meta"``: metadata for the GIfTI pointset array (e.g.
        ``AnatomicalStructurePrimary``, ``GeometricType``); ``"volume_info"``:
        FreeSurfer volume geometry to append to the surface;
        ``"create_stamp"``: FreeSurfer comment line.  Ignored by other families.
    precision : {None, "float32", "float64"}, optional
        Precision of the stored coordinates; None: the format's own
        (:data:`STORED_PRECISION`).  Only GIfTI offers a choice; asking a
        format for a precision it does not store raises ``ValueError``.

    Raises
    ------
    ValueError
        Unknown family or extension, a precision the format does not store,
        non-finite coordinates or coordinates beyond the range of a float32
        format (they would be stored as infinities), shapes other than
        ``(n, 3)`` / ``(m, 3)``, face indices that are not whole numbers in
        ``0..n-1``, or a libigl write failure.
    FileNotFoundError, PermissionError
        The folder does not exist or cannot be written.
    """
    path = Path(path)
    family = family or mesh_format(path, must_exist=False)
    precision = stored_precision(path, precision, family)
    V = np.ascontiguousarray(V, dtype=np.float64)
    if V.ndim != 2 or V.shape[1] != 3 or np.ndim(F) != 2 or np.shape(F)[1] != 3:
        raise ValueError(f"cannot write '{path}': V must be (n, 3) and F (m, 3), got {V.shape} "
                         f"and {np.shape(F)}")
    try:  # integer indices into V: a file with others would be refused when read back
        F = as_faces(F, V.shape[0])
    except ValueError as err:
        raise ValueError(f"cannot write '{path}': {err}") from None
    bad = np.count_nonzero(~np.isfinite(V).all(axis=1))
    if bad:
        raise ValueError(f"cannot write '{path}': {plural(bad, 'vertex has', 'vertices have')} "
                         "non-finite coordinates")
    if precision == "float32":
        big = np.count_nonzero((np.abs(V) > np.finfo(np.float32).max).any(axis=1))
        if big:
            raise ValueError(f"cannot write '{path}': {plural(big, 'vertex has', 'vertices have')} "
                             "coordinates beyond the float32 range "
                             f"(±{np.finfo(np.float32).max:.3g}) that this format stores; scale "
                             "them down (e.g. a smaller radius)")
    with atomic_path(path) as tmp:
        if family == "mesh":
            _write_libigl_family(path, tmp, V, F)
        elif family == "gifti":
            _write_gifti(tmp, V, F, metadata or {}, precision)
        elif family == "freesurfer":
            import nibabel.freesurfer as fs

            metadata = metadata or {}
            stamp = metadata.get("create_stamp", "created by igl-spheremap")
            fs.write_geometry(str(tmp), V, F, create_stamp=stamp,
                              volume_info=metadata.get("volume_info") or None)
        else:
            raise ValueError(f"cannot tell which format to write '{path}' in "
                             f"(family={family!r}); use an extension such as .obj, .off, .ply, "
                             ".surf.gii or a FreeSurfer name such as lh.sphere")


def stored_precision(path, precision=None, family=None):
    """The coordinate precision ``path`` will store (``"float32"``, ``"float64"`` or None).

    Call it before any work to refuse a precision the format cannot store.

    Parameters
    ----------
    path : str or os.PathLike
        Output name (its extension, or ``family``, names the format).
    precision : {None, "float32", "float64"}
        Asked for; None: the format's own (:data:`STORED_PRECISION`).
    family : {"mesh", "gifti", "freesurfer"}, optional
        Default: :func:`igl_spheremap.io.mesh_format` of ``path``.

    Returns
    -------
    str or None
        None for a format whose precision is not known here (libigl's others).

    Raises
    ------
    ValueError
        An unknown ``precision``, or one the format does not store.
    """
    path = Path(path)
    family = family or mesh_format(path, must_exist=False)
    key = path.suffix.lower() if family == "mesh" else family
    if precision not in (None, "float32", "float64"):
        raise ValueError(f"precision must be None, 'float32' or 'float64', not {precision!r}")
    stored = STORED_PRECISION.get(key)
    if precision is None or precision == stored or key == "gifti" or stored is None:
        return precision or stored
    raise ValueError(f"cannot write '{path}' with {precision} coordinates: this format stores "
                     f"{stored}" + ("; use .obj, .off, .ply or .surf.gii with precision='float64'"
                                   if precision == "float64" else ""))


def _write_libigl_family(path, tmp, V, F):
    import igl

    ext = path.suffix.lower()
    if ext in _OWN_WRITERS:
        _OWN_WRITERS[ext](tmp, V, F)
        return
    try:
        if ext == ".stl":
            igl.writeSTL(str(tmp), V, F, True)
        else:
            igl.write_triangle_mesh(str(tmp), V, F)
    except RuntimeError as exc:
        raise ValueError(f"cannot write '{path}': libigl could not write the format "
                         f"'{ext}' ({str(exc).replace(tmp.name, path.name)})") from None


def _write_gifti(tmp, V, F, metadata, precision):
    from nibabel.gifti import GiftiDataArray, GiftiImage, GiftiMetaData

    def meta(key):
        return GiftiMetaData({k: str(v) for k, v in metadata.get(key, {}).items()})

    dtype = np.float64 if precision == "float64" else np.float32
    pts = GiftiDataArray(V.astype(dtype), intent="NIFTI_INTENT_POINTSET",
                         datatype="NIFTI_TYPE_FLOAT64" if precision == "float64"
                         else "NIFTI_TYPE_FLOAT32", meta=meta("gifti_meta"))
    tri = GiftiDataArray(F.astype(np.int32), intent="NIFTI_INTENT_TRIANGLE",
                         datatype="NIFTI_TYPE_INT32", meta=meta("gifti_triangle_meta"))
    # nibabel refuses float64 in its default "strict" mode (outside GIfTI 1.0)
    GiftiImage(darrays=[pts, tri]).to_filename(
        str(tmp), mode="force" if precision == "float64" else "strict")

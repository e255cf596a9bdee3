"""Read a triangle mesh from a libigl, GIfTI or FreeSurfer file."""

import warnings
from pathlib import Path

import numpy as np

from ._stderr import captured_stderr_fd, one_line
from .mesh_format import mesh_format


def read_mesh(path, *, return_metadata=False):
    """Read a triangle mesh; the reader is chosen by :func:`mesh_format`.

    * ``"mesh"`` (``.obj .off .ply .stl .wrl .mesh .msh``): ``igl.read_triangle_mesh``.
      STL stores every triangle with its own corners, so coincident corners are
      merged with ``igl.remove_duplicate_vertices`` (exact matches only).
    * ``"gifti"`` (``.gii``, ``.surf.gii``): ``nibabel.load``; vertices from the
      ``NIFTI_INTENT_POINTSET`` array and faces from the ``NIFTI_INTENT_TRIANGLE``
      array.
    * ``"freesurfer"`` (``lh.white``, ``rh.pial``, ``lh.sphere``... any file
      with a FreeSurfer magic number): ``nibabel.freesurfer.read_geometry``
      (quad files are split into triangles by nibabel).

    Parameters
    ----------
    path : str or os.PathLike
    return_metadata : bool, default False
        Also return a dict of format metadata worth carrying to the output:
        ``volume_info`` (FreeSurfer volume geometry, an ``OrderedDict``) and
        ``gifti_meta`` (the GIfTI pointset array's metadata, a dict).

    Returns
    -------
    V : (n, 3) float64 array
        Vertex positions, in the file's units (FreeSurfer/GIfTI: millimetres,
        stored as float32 in the file).
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
    ValueError
        The format cannot be told from the name or content, the file cannot be
        parsed, or it holds no triangles.
    """
    path = Path(path)
    family = mesh_format(path)
    if family is None:
        raise ValueError(f"cannot tell the mesh format of '{path}': expected one of "
                         ".obj .off .ply .stl .wrl .mesh .msh, .gii/.surf.gii, or a FreeSurfer "
                         "surface (lh.white, rh.pial, ...)")
    meta = {}
    if family == "mesh":
        V, F = _read_igl(path)
    elif family == "gifti":
        V, F, meta["gifti_meta"] = _read_gifti(path)
    else:
        V, F, meta["volume_info"] = _read_freesurfer(path)
    V = np.ascontiguousarray(V, dtype=np.float64)
    F = np.ascontiguousarray(F, dtype=np.int64)
    if F.size == 0 or V.size == 0:
        raise ValueError(f"'{path}' holds no triangles (read {len(V)} vertices, {len(F)} faces)")
    if V.ndim != 2 or V.shape[1] != 3 or F.ndim != 2 or F.shape[1] != 3:
        raise ValueError(f"'{path}' is not a 3-D triangle mesh: V {V.shape}, F {F.shape}")
    if return_metadata:
        return V, F, family, meta
    return V, F, family


def _read_igl(path):
    import igl

    err = []
    try:
        with captured_stderr_fd(err):
            V, F = igl.read_triangle_mesh(str(path))
    except RuntimeError as exc:
        detail = one_line("".join(err))
        raise ValueError(f"cannot read '{path}': {exc}" + (f" ({detail})" if detail else "")) \
            from None
    if path.suffix.lower() == ".stl" and F.size:
        V, _, _, F = igl.remove_duplicate_vertices(V, F, 0.0)
    return V, F


def _read_gifti(path):
    import nibabel as nib

    try:
        img = nib.load(str(path))
    except Exception as exc:  # nibabel raises several types for corrupt XML
        raise ValueError(f"cannot read GIfTI '{path}': {exc}") from None
    points = img.get_arrays_from_intent("NIFTI_INTENT_POINTSET")
    tris = img.get_arrays_from_intent("NIFTI_INTENT_TRIANGLE")
    if len(points) != 1 or len(tris) != 1:
        raise ValueError(f"'{path}' is not a GIfTI surface: it has {len(points)} POINTSET and "
                         f"{len(tris)} TRIANGLE arrays (need one of each)")
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

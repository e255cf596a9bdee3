"""Which reader or writer handles a mesh file: libigl, GIfTI or FreeSurfer."""

import re
import struct
from pathlib import Path

#: Extensions that ``igl.read_triangle_mesh`` / ``igl.write_triangle_mesh`` handle.
IGL_EXTENSIONS = (".obj", ".off", ".ply", ".stl", ".wrl", ".mesh", ".msh")

#: Name endings of GIfTI files (``.surf.gii``, ``.func.gii``, ...), gzip-compressed as nilearn
#: ships FreeSurfer's fsaverage (``white_left.gii.gz``) or not; nibabel reads and writes both.
GIFTI_SUFFIXES = (".gii", ".gii.gz")

#: First three bytes of FreeSurfer surfaces: triangle, quad and "new quad" files.
FREESURFER_MAGIC = (b"\xff\xff\xfe", b"\xff\xff\xff", b"\xff\xff\xfd")

#: First three bytes of FreeSurfer's (new) curv format, shared with quad surfaces.
CURV_MAGIC = b"\xff\xff\xff"

#: Bytes before the values of a curv file: magic, int32 vertices, faces, values per vertex.
CURV_HEADER = 15

_HEMI_NAME = re.compile(r"^[a-z]h\.", re.IGNORECASE)  # lh.white, rh.pial, ?h.sphere


def mesh_format(path, *, must_exist=True):
    """Format family of a mesh file: ``"mesh"``, ``"gifti"`` or ``"freesurfer"``.

    Rules, in order:

    1. a name ending in ``.gii`` (``.surf.gii``, ``.gii``) or ``.gii.gz`` is GIfTI;
    2. an extension in :data:`IGL_EXTENSIONS` (case-insensitive) is a libigl
       mesh file;
    3. an existing FreeSurfer per-vertex data file in the curv format
       (``lh.sulc``, ``lh.thickness``: :func:`curv_layout`) is no mesh (None);
    4. an existing file starting with a FreeSurfer magic number
       (:data:`FREESURFER_MAGIC`) is a FreeSurfer surface, whatever its name;
    5. a name like ``lh.white``, ``rh.pial``, ``lh.sphere.reg`` (two letters
       ending in ``h``, then a dot) is a FreeSurfer surface.

    Parameters
    ----------
    path : str or os.PathLike
    must_exist : bool, default True
        Raise ``FileNotFoundError`` when ``path`` does not exist (set False to
        classify an output name).

    Returns
    -------
    str or None
        The family, or None when no rule applies.

    Raises
    ------
    FileNotFoundError
        ``must_exist`` and ``path`` is missing.
    IsADirectoryError
        ``must_exist`` and ``path`` is a folder.
    """
    path = Path(path)
    if must_exist and path.is_dir():
        raise IsADirectoryError(f"'{path}' is a folder, not a mesh file")
    if must_exist and not path.is_file():
        raise FileNotFoundError(f"no such file: '{path}'")
    name = path.name.lower()
    if name.endswith(GIFTI_SUFFIXES):
        return "gifti"
    if path.suffix.lower() in IGL_EXTENSIONS:
        return "mesh"
    if path.is_file():
        if curv_layout(path) is not None:
            return None
        if is_freesurfer_surface(path):
            return "freesurfer"
    if _HEMI_NAME.match(path.name):
        return "freesurfer"
    return None


def is_freesurfer_surface(path):
    """Whether ``path`` starts with a FreeSurfer surface's magic number and is no curv file.

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    bool
        False also for a missing or unreadable file.
    """
    try:
        with open(path, "rb") as fh:
            magic = fh.read(3)
    except OSError:  # missing or unreadable: the reader names the problem
        return False
    return magic in FREESURFER_MAGIC and curv_layout(path) is None


def curv_layout(path):
    """Vertex count and values per vertex of a FreeSurfer curv (morphometry) file, else None.

    The curv format (``lh.sulc``, ``lh.curv``, ``lh.thickness``): the bytes
    ``ff ff ff`` (also the magic of quad surfaces), big-endian int32 vertex
    count ``N``, face count and values per vertex ``k``, then ``N * k`` float32
    values; the file is recognised only when its size is exactly
    ``15 + 4 * N * k`` bytes.

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    (int, int) or None
        ``(N, k)``, or None when the file is not one (or is missing or unreadable).
    """
    try:
        with open(path, "rb") as fh:
            head = fh.read(CURV_HEADER)
            size = fh.seek(0, 2)
    except OSError:
        return None
    if len(head) < CURV_HEADER or head[:3] != CURV_MAGIC:
        return None
    n, _, k = struct.unpack(">iii", head[3:])
    if n <= 0 or k <= 0 or size != CURV_HEADER + 4 * n * k:
        return None
    return n, k

"""Which reader or writer handles a mesh file: libigl, GIfTI or FreeSurfer."""

import re
from pathlib import Path

#: Extensions that ``igl.read_triangle_mesh`` / ``igl.write_triangle_mesh`` handle.
IGL_EXTENSIONS = (".obj", ".off", ".ply", ".stl", ".wrl", ".mesh", ".msh")

#: Name endings of GIfTI files (``.surf.gii``, ``.func.gii``, ...), gzip-compressed as nilearn
#: ships FreeSurfer's fsaverage (``white_left.gii.gz``) or not; nibabel reads and writes both.
GIFTI_SUFFIXES = (".gii", ".gii.gz")

#: First three bytes of FreeSurfer surfaces: triangle, quad and "new quad" files.
FREESURFER_MAGIC = (b"\xff\xff\xfe", b"\xff\xff\xff", b"\xff\xff\xfd")

_HEMI_NAME = re.compile(r"^[a-z]h\.", re.IGNORECASE)  # lh.white, rh.pial, ?h.sphere


def mesh_format(path, *, must_exist=True):
    """Format family of a mesh file: ``"mesh"``, ``"gifti"`` or ``"freesurfer"``.

    Rules, in order:

    1. a name ending in ``.gii`` (``.surf.gii``, ``.gii``) or ``.gii.gz`` is GIfTI;
    2. an extension in :data:`IGL_EXTENSIONS` (case-insensitive) is a libigl
       mesh file;
    3. an existing file starting with a FreeSurfer magic number
       (:data:`FREESURFER_MAGIC`) is a FreeSurfer surface, whatever its name;
    4. a name like ``lh.white``, ``rh.pial``, ``lh.sphere.reg`` (two letters
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
        try:
            with open(path, "rb") as fh:
                if fh.read(3) in FREESURFER_MAGIC:
                    return "freesurfer"
        except OSError:  # unreadable: the reader names the problem
            pass
    if _HEMI_NAME.match(path.name):
        return "freesurfer"
    return None

"""Folded faces of the map a file stores, read back from the file."""

import numpy as np

from ..errors import plural
from ..mesh.validate import power_of_two_scaled
from ..sphere.folds import count_folds
from .read_mesh import read_mesh


def stored_folds(path, F=None):
    """Number of folded faces of the spherical map stored in ``path``, as read back.

    The map in memory can be fold-free while the file is not: formats round
    the coordinates, and the smallest image triangles of a crowded conformal
    map (areas down to 1e-21) flip under that rounding.  This reads the file
    with :func:`read_mesh` and counts folds (faces whose image has signed
    volume <= 0, :func:`igl_spheremap.sphere.folds.count_folds`) of what it stores.
    The sphere's radius does not change the signs (the coordinates read are scaled by a
    power of two, exactly, so that no determinant overflows).

    Rounding of each output (see :func:`write_mesh`): ``.obj``, ``.off``,
    ``.ply`` none (exact float64); ``.surf.gii`` float32 (float64 with
    ``precision="float64"``); FreeSurfer float32; ``.stl`` float32 per corner,
    and its corners are merged back into vertices by exact match.

    Parameters
    ----------
    path : str or os.PathLike
        A sphere just written.
    F : (m, 3) int array, optional
        The outward-oriented faces that were written (0-based); default the
        faces read back.  Not usable with STL, whose vertices are renumbered.

    Returns
    -------
    int
        Folded faces of the stored map.

    Raises
    ------
    ValueError
        The file cannot be read (see :func:`read_mesh`), or ``F`` does not fit
        the vertices read back (shape, index range).
    FileNotFoundError
        ``path`` does not exist.
    """
    V, F_read, _ = read_mesh(path)
    # exact: near float64's limits (radius 1e308) the determinants would overflow to NaN
    V = power_of_two_scaled(V, np.ones(len(V), dtype=bool))[0]
    if F is None:
        return count_folds(F_read, V)
    F = np.asarray(F)
    if F.ndim != 2 or F.shape[1] != 3 or F.size == 0 or F.min() < 0 or F.max() >= len(V):
        raise ValueError(f"the faces given do not fit the {plural(len(V), 'vertex', 'vertices')} "
                         f"read from '{path}' (F of shape {F.shape}"
                         + (f", indices {F.min()}..{F.max()})" if F.size else ")"))
    return count_folds(F.astype(np.int64), V)

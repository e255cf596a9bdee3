"""Read a Gmsh ``.msh`` triangle mesh with ``meshio``: libigl's Gmsh reader hangs on some files."""

import warnings

import numpy as np

from .check_obj import TextMesh

#: meshio's names of surface elements other than 3-node triangles (not read: refused).
OTHER_SURFACE_CELLS = ("quad", "triangle6", "triangle7", "quad8", "quad9", "polygon")


def read_msh(path):
    """Read the vertices and 3-node triangles of a Gmsh file (2.2 or 4.x, ASCII or binary).

    libigl's Gmsh reader (2.6.3) loops forever when a number in the file does not parse
    (its stream fails short of the end, and its loops test only for the end: a damaged
    digit, a carriage return inside a number, a negative tag count), and writes node
    coordinates at the node tags it reads without a bound check.  So Gmsh files are read
    here with ``meshio``, which raises on what it cannot parse.

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    TextMesh
        ``V`` (n, 3) float64, every node of the file in its order; ``F`` (m, 3) int64,
        the 3-node triangles (other elements, such as the tetrahedra of a volume mesh or
        boundary lines, are left out); ``polygons`` 0.

    Raises
    ------
    ValueError
        ``meshio`` cannot parse the file (its message), it has no 3-node triangles (the
        element counts it has), or it has other surface elements (quadrangles,
        second-order triangles: their counts), which would be lost.
    """
    import meshio.gmsh  # the format's reader itself: meshio.read ends the process on failure

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            mesh = meshio.gmsh.read(str(path))
    except Exception as exc:  # meshio raises its ReadError, numpy's and struct's errors
        why = str(exc) or type(exc).__name__
        raise ValueError(f"cannot read '{path}' as a Gmsh file: {why}") from None
    counts = {}
    for block in mesh.cells:
        counts[block.type] = counts.get(block.type, 0) + len(block.data)
    listed = ", ".join(f"{count} {kind}" for kind, count in counts.items()) or "none"
    other = {kind: counts[kind] for kind in OTHER_SURFACE_CELLS if kind in counts}
    if other:
        raise ValueError(f"'{path}' has surface elements other than 3-node triangles, which "
                         f"would be lost: {', '.join(f'{c} {k}' for k, c in other.items())}; "
                         "split them into 3-node triangles first")
    if "triangle" not in counts:
        raise ValueError(f"'{path}' holds no 3-node triangles (its elements: {listed})")
    F = np.concatenate([np.asarray(b.data, dtype=np.int64) for b in mesh.cells
                        if b.type == "triangle"])
    return TextMesh(np.asarray(mesh.points, dtype=np.float64), F, 0)

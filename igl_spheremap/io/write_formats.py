"""Writers of the formats libigl writes with too few digits: OBJ, OFF (text) and PLY (binary).

libigl 2.6.3 writes OBJ and OFF coordinates with 15 significant digits and
ASCII PLY with 6, so a written map is not the map in memory (checked in
``tests/test_io_precision.py``).  These writers store every float64 exactly.
"""

import numpy as np


def _repr_lines(prefix, rows):
    """``prefix`` + the shortest round-trip decimal of each number (Python's ``repr``), per row."""
    if len(rows) == 0:
        return ""
    fmt = (prefix + " ".join(["%r"] * rows.shape[1]) + "\n") * len(rows)
    return fmt % tuple(rows.ravel().tolist())


def write_obj(path, V, F):
    """Write ``v x y z`` / ``f i j k`` lines (1-based), coordinates as round-trip decimals.

    Each coordinate is the shortest decimal that reads back to the same
    float64 (Python's ``repr``, at most 17 significant digits).

    Parameters
    ----------
    path : str or os.PathLike
    V : (n, 3) float64 array
        Finite.
    F : (m, 3) int64 array
        0-based.
    """
    text = _repr_lines("v ", V) + _repr_lines("f ", F + 1)
    with open(path, "w", encoding="ascii", newline="\n") as fh:
        fh.write(text)


def write_off(path, V, F):
    """Write ``OFF``, ``x y z`` and ``3 i j k`` lines (0-based), coordinates as round-trip decimals.

    Parameters
    ----------
    path : str or os.PathLike
    V : (n, 3) float64 array
        Finite.
    F : (m, 3) int64 array
        0-based.
    """
    faces = np.column_stack([np.full(len(F), 3, dtype=np.int64), F])
    text = f"OFF\n{len(V)} {len(F)} 0\n" + _repr_lines("", V) + _repr_lines("", faces)
    with open(path, "w", encoding="ascii", newline="\n") as fh:
        fh.write(text)


def write_ply(path, V, F):
    """Write binary little-endian PLY: float64 ``x y z``, ``int32`` face lists (``uchar`` count).

    Written with the ``plyfile`` package.

    Parameters
    ----------
    path : str or os.PathLike
    V : (n, 3) float64 array
    F : (m, 3) int64 array
        0-based, below 2**31.
    """
    from plyfile import PlyData, PlyElement

    vertex = np.empty(len(V), dtype=[("x", "<f8"), ("y", "<f8"), ("z", "<f8")])
    vertex["x"], vertex["y"], vertex["z"] = V[:, 0], V[:, 1], V[:, 2]
    face = np.empty(len(F), dtype=[("vertex_indices", "<i4", (3,))])
    face["vertex_indices"] = F
    elements = [PlyElement.describe(vertex, "vertex"),
                PlyElement.describe(face, "face", len_types={"vertex_indices": "u1"},
                                    val_types={"vertex_indices": "i4"})]
    PlyData(elements, text=False, byte_order="<").write(str(path))

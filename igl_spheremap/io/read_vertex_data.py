"""Read per-vertex files (curvature, thickness, labels, masks) for the registration and resampling
commands: values, integer labels with their table, and masks."""

from pathlib import Path

import numpy as np

from ..errors import plural
from .mesh_format import CURV_MAGIC, FREESURFER_MAGIC, GIFTI_SUFFIXES, IGL_EXTENSIONS


#: Magic numbers that only FreeSurfer surfaces have (the curv files' ``0xFFFFFF`` is shared
#: by quad surfaces, and a damaged curv file must reach its reader's message).
SURFACE_MAGIC = tuple(m for m in FREESURFER_MAGIC if m != CURV_MAGIC)

#: Name endings of FreeSurfer's MGH volumes, which hold surface overlays as (n, 1, 1[, k]).
MGH_SUFFIXES = (".mgh", ".mgz")

#: What a FreeSurfer annotation / label file is, and where to pass it.
ANNOT = ("a FreeSurfer annotation (a label per vertex and a colour table)",
         "pass it as labels (--labels; read_vertex_labels)")
LABEL = ("a FreeSurfer label file (a list of vertex indices)",
         "pass it as a mask (--mask; read_vertex_mask)")

#: Largest magnitude up to which every integer is a float64.
EXACT_FLOAT_INTEGERS = 2 ** 53


def read_vertex_data(path, vertices=None):
    """Per-vertex values from a file.

    * ``.npy``: one array; ``.npz``: its arrays, stacked as columns in the
      file's order; ``.txt`` / ``.csv``: ``numpy.loadtxt`` (whitespace or commas).
    * ``.gii`` (``.func.gii``, ``.shape.gii``, ``.label.gii``), gzip-compressed
      (``.gii.gz``) or not: the GIfTI data arrays, as columns, through nibabel.
    * ``.mgh`` / ``.mgz`` (FreeSurfer surface overlays such as
      ``lh.thickness.fwhm10.fsaverage.mgh``): the volume of shape ``(n, 1, 1)``
      or ``(n, 1, 1, k)`` through nibabel, as ``(n,)`` or ``(n, k)``.
    * FreeSurfer morphometry files (``lh.thickness``, ``rh.curv``, ``lh.sulc``,
      ...; anything else nibabel's ``read_morph_data`` reads).

    A FreeSurfer ``.annot`` (labels: :func:`read_vertex_labels`) or ``.label``
    (a vertex list: :func:`read_vertex_mask`) is refused with that hint.

    Parameters
    ----------
    path : str or os.PathLike
    vertices : int, optional
        Required number of rows.

    Returns
    -------
    values : (n,) or (n, d) float64 array
    names : list of str
        A name per column (array names of ``.npz`` / GIfTI, else the file's name).

    Raises
    ------
    FileNotFoundError
        ``path`` does not exist.
    ValueError
        The file cannot be read as per-vertex data (a FreeSurfer surface, an
        ``.annot`` or ``.label`` file, an MGH volume not of shape ``(n, 1, 1[, k])``, a
        damaged file, whatever the error its reader raised), holds non-finite values,
        or has a number of rows other than ``vertices``.
    """
    path = Path(path)
    _refuse(path, ANNOT, "per-vertex data", ".annot")
    _refuse(path, LABEL, "per-vertex data", ".label")
    X, names, _ = _load(path)
    if not (np.issubdtype(X.dtype, np.number) or X.dtype == bool):
        raise ValueError(f"'{path}' holds {X.dtype} values, not numbers")
    return _rows(path, X.astype(np.float64), vertices), names


def read_vertex_labels(path, vertices=None):
    """One integer label per vertex, and the file's label table when it has one.

    * FreeSurfer ``.annot`` (``nibabel.freesurfer.read_annot``): the index of
      each vertex's entry in the colour table (-1: in none), and that table.
    * GIfTI (``.label.gii``): the one data array, and the file's label table.
    * any other file :func:`read_vertex_data` reads, with one column of whole
      numbers (no table).

    Parameters
    ----------
    path : str or os.PathLike
    vertices : int, optional
        Required number of rows.

    Returns
    -------
    labels : (n,) int64 array
    table : dict of int -> (str, (float, float, float, float)) or None
        Label key -> name and RGBA colour in ``[0, 1]``, as in a GIfTI label
        table (:func:`igl_spheremap.io.write_vertex_data` writes it back).

    Raises
    ------
    FileNotFoundError
        ``path`` does not exist.
    ValueError
        As :func:`read_vertex_data`; also a ``.label`` file (a vertex list: a
        mask), more than one column, values that are not whole numbers (count
        and first row named) or whole numbers beyond ``2**53`` stored as floats.
    """
    path = Path(path)
    _refuse(path, LABEL, "labels", ".label")
    X, _, table = _load(path)
    if not (np.issubdtype(X.dtype, np.number) or X.dtype == bool):
        raise ValueError(f"'{path}' holds {X.dtype} values, not integer labels")
    if np.issubdtype(X.dtype, np.floating):
        finite = np.isfinite(X)
        bad = ~finite | (X != np.round(np.where(finite, X, 0))) | \
            (np.abs(np.where(finite, X, 0)) > EXACT_FLOAT_INTEGERS)
        _rows(path, X, vertices)  # shape, rows and non-finite values first
        if bad.any():
            first = int(np.flatnonzero(bad.reshape(len(X), -1).any(axis=1))[0])
            what = plural(int(bad.sum()), "value is not a whole number",
                          "values are not whole numbers")
            raise ValueError(f"'{path}' must hold one integer label per vertex: {what} (or beyond "
                             f"2**53 as floats), first in row {first}: "
                             f"{X.reshape(len(X), -1)[first]}")
    L = _rows(path, X.astype(np.int64), vertices)
    if L.ndim != 1:
        raise ValueError(f"'{path}' must hold one integer label per vertex, not {L.shape[1]} "
                         "columns")
    return L, table


def read_vertex_mask(path, vertices):
    """Which vertices to use: a FreeSurfer ``.label`` file's vertices, or values > 0.

    * FreeSurfer ``.label`` (``cortex.label``; ``nibabel.freesurfer.read_label``):
      True at the vertices it lists.
    * any other file :func:`read_vertex_data` reads, with one column: True where
      the value is > 0.

    Parameters
    ----------
    path : str or os.PathLike
    vertices : int
        Number of vertices of the mesh the mask is of.

    Returns
    -------
    (vertices,) bool array

    Raises
    ------
    FileNotFoundError
        ``path`` does not exist.
    ValueError
        As :func:`read_vertex_data`; also an ``.annot`` (labels, not a mask), more
        than one column, or a ``.label`` file that cannot be read or lists vertex
        indices outside ``0..vertices-1`` (their count and the first named).
    """
    path = Path(path)
    _refuse(path, ANNOT, "a mask", ".annot")
    if path.name.lower().endswith(".label"):
        index, _, _ = _load(path)
        bad = (index < 0) | (index >= vertices)
        if bad.any():
            what = plural(int(bad.sum()), "vertex index", "vertex indices")
            raise ValueError(f"'{path}' lists {what} outside 0..{vertices - 1} (first: "
                             f"{int(index[bad][0])}): it is the label of another mesh (or a "
                             "volume label)")
        M = np.zeros(vertices, dtype=bool)
        M[index] = True
        return M
    X, _ = read_vertex_data(path, vertices)
    if X.ndim != 1:
        raise ValueError(f"'{path}' must hold one mask value per vertex, not {X.shape[1]} "
                         "columns")
    return X > 0


def _refuse(path, kind, role, suffix):
    if path.name.lower().endswith(suffix):
        raise ValueError(f"'{path}' is {kind[0]}, not {role}: {kind[1]}")


def _load(path):
    """``(array as stored, column names, label table or None)`` of a per-vertex file; every
    reader's error a ValueError naming the file."""
    if not path.is_file():
        raise FileNotFoundError(f"no such data file: '{path}'")
    with open(path, "rb") as fh:
        if fh.read(3) in SURFACE_MAGIC:
            raise ValueError(f"'{path}' is a FreeSurfer surface (vertices and faces), not "
                             "per-vertex data; pass it as a mesh, and its data as e.g. lh.sulc, "
                             ".func.gii or .npy")
    if path.suffix.lower() in IGL_EXTENSIONS:
        raise ValueError(f"'{path}' is a mesh file ({path.suffix}), not per-vertex data; pass it "
                         "as a mesh, and its data as e.g. .npy, .func.gii or lh.sulc")
    try:
        X, names, table = _read(path, path.name.lower())
    except (OSError, ValueError) as exc:
        raise ValueError(f"cannot read per-vertex data from '{path}': {exc}") from None
    except Exception as exc:  # on a damaged file numpy, zipfile, zlib, expat and nibabel raise
        raise ValueError(f"cannot read per-vertex data from '{path}': "  # many other types
                         f"{type(exc).__name__}: {exc}") from None
    return np.asarray(X), names, table


def _rows(path, X, vertices):
    """``X`` (a column squeezed) after checking its shape, row count and finiteness."""
    if X.ndim == 2 and X.shape[1] == 1:
        X = X[:, 0]
    if X.ndim not in (1, 2) or X.size == 0:
        raise ValueError(f"'{path}' holds an array of shape {X.shape}, not per-vertex values")
    if vertices is not None and X.shape[0] != vertices:
        raise ValueError(f"'{path}' has {plural(X.shape[0], 'row')} but the mesh has {vertices} "
                         "vertices")
    if np.issubdtype(X.dtype, np.floating):
        bad = ~np.isfinite(X).reshape(X.shape[0], -1).all(axis=1)
        if bad.any():
            raise ValueError(f"'{path}' has {plural(int(bad.sum()), 'row')} with NaN or infinite "
                             "values (a medial wall's NaN? set those vertices to 0 and leave them "
                             "out with a mask, --mask)")
    return X


def _read(path, name):
    if name.endswith(".npy"):
        return np.load(path, allow_pickle=False), [path.stem], None
    if name.endswith(".npz"):
        with np.load(path, allow_pickle=False) as z:
            names = list(z.files)
            if not names:
                raise ValueError("the .npz archive holds no arrays")
            return np.column_stack([np.asarray(z[k]).reshape(len(z[k]), -1) for k in names]), \
                names, None
    if name.endswith((".txt", ".csv")):
        return np.loadtxt(path, delimiter="," if name.endswith(".csv") else None,
                          ndmin=1), [path.stem], None
    if name.endswith(GIFTI_SUFFIXES):
        return _read_gifti(path)
    if name.endswith(MGH_SUFFIXES):
        return _read_mgh(path), [path.name], None
    import nibabel.freesurfer as fs

    if name.endswith(".annot"):
        labels, ctab, names = fs.read_annot(str(path))
        return labels, [path.name], {i: (n.decode(errors="replace"),
                                         tuple(float(c) / 255 for c in (r, g, b, 255 - t)))
                                     for i, ((r, g, b, t, _), n) in enumerate(zip(ctab, names))}
    if name.endswith(".label"):
        return _read_label(path, fs), [path.name], None
    return fs.read_morph_data(str(path)), [path.name], None


def _read_gifti(path):
    import nibabel as nib

    img = nib.load(str(path))
    if img.get_arrays_from_intent("NIFTI_INTENT_TRIANGLE"):
        raise ValueError("it is a GIfTI surface (vertices and triangles), not per-vertex "
                         "data; pass it as a mesh, and its data as a .func.gii or .shape.gii")
    names = [a.meta.get("Name", f"array{i}") for i, a in enumerate(img.darrays)]
    table = {int(lab.key): (lab.label or str(lab.key),
                            tuple(float(c) if c is not None else 1.0 for c in
                                  (lab.red, lab.green, lab.blue, lab.alpha)))
             for lab in img.labeltable.labels} or None
    return np.column_stack([a.data for a in img.darrays]), names, table


def _read_label(path, fs):
    """The vertex indices of a FreeSurfer ``.label`` file, checked against the count its second
    line states (nibabel's ``read_label`` reads whatever rows there are: a truncated file would
    be a smaller mask)."""
    with open(path, "rb") as fh:
        fh.readline()
        stated = fh.readline().strip()
    index = np.atleast_1d(fs.read_label(str(path)))
    if not stated.isdigit() or int(stated) != index.size:
        raise ValueError(f"its second line states {stated.decode(errors='replace')!r} vertices "
                         f"but it lists {index.size}: a truncated or edited label file")
    return index


def _read_mgh(path):
    """An MGH overlay ``(n, 1, 1)`` / ``(n, 1, 1, k)`` as ``(n,)`` / ``(n, k)``."""
    import nibabel as nib

    X = np.asarray(nib.load(str(path)).dataobj)
    if X.ndim not in (3, 4) or X.shape[1:3] != (1, 1):
        raise ValueError(f"it holds a volume of shape {X.shape}, not per-vertex values (a surface "
                         "overlay is (n, 1, 1) or (n, 1, 1, k), n the vertex count)")
    return X.reshape(X.shape[0], -1)

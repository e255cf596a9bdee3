"""Read per-vertex data and landmark lists for the registration and resampling commands."""

from pathlib import Path

import numpy as np


def read_vertex_data(path, vertices=None):
    """Per-vertex values from a file.

    * ``.npy``: one array; ``.npz``: its arrays, stacked as columns in the
      file's order; ``.txt`` / ``.csv``: ``numpy.loadtxt`` (whitespace or commas).
    * ``.gii`` (``.func.gii``, ``.shape.gii``, ``.label.gii``): the GIfTI data
      arrays, as columns, through nibabel.
    * FreeSurfer morphometry files (``lh.thickness``, ``rh.curv``, ``lh.sulc``,
      ...; anything else nibabel's ``read_morph_data`` reads).

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
        The file cannot be read as per-vertex data, holds non-finite values, or
        has a number of rows other than ``vertices``.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no such data file: '{path}'")
    name = path.name.lower()
    try:
        X, names = _read(path, name)
    except (OSError, ValueError) as exc:
        raise ValueError(f"cannot read per-vertex data from '{path}': {exc}") from None
    X = np.asarray(X, dtype=np.float64)
    if X.ndim == 2 and X.shape[1] == 1:
        X = X[:, 0]
    if X.ndim not in (1, 2) or X.size == 0:
        raise ValueError(f"'{path}' holds an array of shape {X.shape}, not per-vertex values")
    if vertices is not None and X.shape[0] != vertices:
        raise ValueError(f"'{path}' has {X.shape[0]} rows but the mesh has {vertices} vertices")
    bad = ~np.isfinite(X).reshape(X.shape[0], -1).all(axis=1)
    if bad.any():
        raise ValueError(f"'{path}' has {int(bad.sum())} rows with NaN or infinite values")
    return X, names


def _read(path, name):
    if name.endswith(".npy"):
        return np.load(path, allow_pickle=False), [path.stem]
    if name.endswith(".npz"):
        with np.load(path, allow_pickle=False) as z:
            names = list(z.files)
            return np.column_stack([np.asarray(z[k]).reshape(len(z[k]), -1) for k in names]), \
                names
    if name.endswith((".txt", ".csv")):
        return np.loadtxt(path, delimiter="," if name.endswith(".csv") else None,
                          ndmin=1), [path.stem]
    import nibabel as nib

    if name.endswith(".gii"):
        img = nib.load(str(path))
        names = [a.meta.get("Name", f"array{i}") for i, a in enumerate(img.darrays)]
        return np.column_stack([a.data for a in img.darrays]), names
    import nibabel.freesurfer as fs

    return fs.read_morph_data(str(path)), [path.name]


def read_landmarks(path, V):
    """Landmark vertices from a text file: one vertex index per line, or ``x y z`` rows.

    Rows of three numbers are points, each snapped to the nearest vertex of ``V``
    (Euclidean); rows of one integer are 0-based vertex indices.  Blank lines and
    lines starting with ``#`` are skipped.

    Parameters
    ----------
    path : str or os.PathLike
    V : (n, 3) float64 array
        The surface's vertices.

    Returns
    -------
    (k,) int64 array

    Raises
    ------
    FileNotFoundError
        ``path`` does not exist.
    ValueError
        Rows that are neither one integer nor three numbers (count and first
        line given), or indices outside ``0..n-1``.
    """
    from scipy.spatial import cKDTree

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no such landmark file: '{path}'")
    rows, bad = [], []
    for i, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
        text = line.split("#", 1)[0].replace(",", " ").split()
        if not text:
            continue
        try:
            values = [float(t) for t in text]
        except ValueError:
            values = []
        if len(values) == 1 and float(values[0]).is_integer():
            rows.append((int(values[0]), None))
        elif len(values) == 3 and np.all(np.isfinite(values)):
            rows.append((None, values))
        else:
            bad.append(i)
    if bad:
        raise ValueError(f"{len(bad)} lines of '{path}' are neither a vertex index nor 'x y z' "
                         f"(first: line {bad[0]})")
    points = [v for _, v in rows if v is not None]
    snapped = iter(cKDTree(V).query(np.array(points))[1]) if points else iter(())
    lm = np.array([i if i is not None else next(snapped) for i, _ in rows], dtype=np.int64)
    out = (lm < 0) | (lm >= len(V))
    if out.any():
        raise ValueError(f"{int(out.sum())} landmark indices in '{path}' outside 0..{len(V) - 1}")
    return lm

"""Read per-vertex data (curvature, thickness, labels, ...) for the registration and resampling commands."""

from pathlib import Path

import numpy as np

from .mesh_format import GIFTI_SUFFIXES, IGL_EXTENSIONS


#: Magic numbers of FreeSurfer triangle surfaces (``0xFFFFFF`` is shared by quad
#: surfaces and morphometry files, so it is not one of them).
SURFACE_MAGIC = (b"\xff\xff\xfe", b"\xff\xff\xfd")


def read_vertex_data(path, vertices=None):
    """Per-vertex values from a file.

    * ``.npy``: one array; ``.npz``: its arrays, stacked as columns in the
      file's order; ``.txt`` / ``.csv``: ``numpy.loadtxt`` (whitespace or commas).
    * ``.gii`` (``.func.gii``, ``.shape.gii``, ``.label.gii``), gzip-compressed
      (``.gii.gz``) or not: the GIfTI data arrays, as columns, through nibabel.
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
        The file cannot be read as per-vertex data (a FreeSurfer surface, say, or a
        damaged file, whatever the error its reader raised), holds non-finite values,
        or has a number of rows other than ``vertices``.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no such data file: '{path}'")
    with open(path, "rb") as fh:
        if fh.read(3) in SURFACE_MAGIC:
            raise ValueError(f"'{path}' is a FreeSurfer surface (vertices and faces), not "
                             "per-vertex data; pass it as a mesh, and its data as e.g. lh.sulc, "
                             ".func.gii or .npy")
    name = path.name.lower()
    if path.suffix.lower() in IGL_EXTENSIONS:
        raise ValueError(f"'{path}' is a mesh file ({path.suffix}), not per-vertex data; pass it "
                         "as a mesh, and its data as e.g. .npy, .func.gii or lh.sulc")
    try:
        X, names = _read(path, name)
    except (OSError, ValueError) as exc:
        raise ValueError(f"cannot read per-vertex data from '{path}': {exc}") from None
    except Exception as exc:  # on a damaged file numpy, zipfile, zlib, expat and nibabel raise
        raise ValueError(f"cannot read per-vertex data from '{path}': "  # many other types
                         f"{type(exc).__name__}: {exc}") from None
    X = np.asarray(X)
    if not (np.issubdtype(X.dtype, np.number) or X.dtype == bool):
        raise ValueError(f"'{path}' holds {X.dtype} values, not numbers")
    X = X.astype(np.float64)
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
            if not names:
                raise ValueError("the .npz archive holds no arrays")
            return np.column_stack([np.asarray(z[k]).reshape(len(z[k]), -1) for k in names]), \
                names
    if name.endswith((".txt", ".csv")):
        return np.loadtxt(path, delimiter="," if name.endswith(".csv") else None,
                          ndmin=1), [path.stem]
    import nibabel as nib

    if name.endswith(GIFTI_SUFFIXES):
        img = nib.load(str(path))
        if img.get_arrays_from_intent("NIFTI_INTENT_TRIANGLE"):
            raise ValueError("it is a GIfTI surface (vertices and triangles), not per-vertex "
                             "data; pass it as a mesh, and its data as a .func.gii or .shape.gii")
        names = [a.meta.get("Name", f"array{i}") for i, a in enumerate(img.darrays)]
        return np.column_stack([a.data for a in img.darrays]), names
    import nibabel.freesurfer as fs

    return fs.read_morph_data(str(path)), [path.name]

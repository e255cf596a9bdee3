"""Write named per-vertex arrays (values and integer labels) as NumPy ``.npz`` or GIfTI."""

import colorsys
from pathlib import Path

import numpy as np

from ..errors import plural
from .atomic import atomic_path
from .mesh_format import GIFTI_SUFFIXES

#: Name endings of GIfTI label files, which hold label arrays only.
LABEL_GIFTI_SUFFIXES = (".label.gii", ".label.gii.gz")


def check_data_output(path):
    """Raise a ValueError unless ``path``'s name is one :func:`write_vertex_data` writes
    (``.gii`` / ``.gii.gz`` GIfTI or ``.npz``): called before the work, as
    :func:`igl_spheremap.io.check_sphere_output` is for spheres.

    Parameters
    ----------
    path : str or os.PathLike

    Raises
    ------
    ValueError
        Another extension, named.
    """
    name = Path(path).name.lower()
    if not name.endswith((*GIFTI_SUFFIXES, ".npz")):
        raise ValueError("per-vertex data goes to a .func.gii/.shape.gii/.label.gii (or .gii.gz) "
                         f"or .npz file, not '{Path(path).name}'")


def write_vertex_data(path, data, *, metadata=None, label_table=None):
    """Write per-vertex arrays, atomically; format from the name of ``path``.

    * ``*.gii`` (``.func.gii``, ``.shape.gii``, ``.label.gii``; ``.gii.gz``
      gzip-compressed): one GIfTI data array per entry, in the order of
      ``data``, its key in the array's ``Name`` metadata.  Arrays of an integer
      dtype are labels: int32, ``NIFTI_INTENT_LABEL``, with the file's label
      table (``label_table``, completed by an entry named by its number for
      every other label present); the others (bool included) are values:
      float32, ``NIFTI_INTENT_NONE``.  A ``.label.gii`` takes label arrays
      only.  Loadable in FreeSurfer's freeview, Connectome Workbench and nibabel.
    * ``*.npz``: ``numpy.savez_compressed`` with the keys of ``data``, dtypes kept.

    Parameters
    ----------
    path : str or os.PathLike
    data : dict of str -> (n,) array
        All arrays must have the same length ``n`` (the vertex count).
    metadata : dict, optional
        GIfTI only: file-level metadata (e.g. ``AnatomicalStructurePrimary``).
    label_table : dict of int -> (str, (float, float, float, float)), optional
        GIfTI only: label key -> name and RGBA colour in ``[0, 1]``
        (:func:`igl_spheremap.io.read_vertex_labels` returns it).

    Raises
    ------
    ValueError
        Arrays of different lengths or not 1-D, an extension other than
        ``.gii`` / ``.gii.gz`` / ``.npz``, for GIfTI labels outside the int32
        range (their count: the format stores int32), or arrays that are not
        labels for a ``.label.gii``.  Nothing is written then.
    """
    path = Path(path)
    check_data_output(path)
    arrays = {k: np.asarray(v) for k, v in data.items()}
    sizes = {v.shape for v in arrays.values()}
    if len(sizes) != 1 or len(next(iter(sizes))) != 1:
        raise ValueError(f"per-vertex arrays must be 1-D and of one length; got shapes {sizes}")
    if path.name.lower().endswith(GIFTI_SUFFIXES):
        _write_gifti(path, arrays, metadata, label_table)
    else:
        with atomic_path(path) as tmp:
            with open(tmp, "wb") as fh:  # a file object keeps savez from appending ".npz"
                np.savez_compressed(fh, **arrays)


def _is_label(v):
    return np.issubdtype(v.dtype, np.integer)


def _write_gifti(path, arrays, metadata, label_table):
    import nibabel as nib
    from nibabel.gifti import GiftiDataArray, GiftiImage, GiftiMetaData

    values = [k for k, v in arrays.items() if not _is_label(v)]
    if path.name.lower().endswith(LABEL_GIFTI_SUFFIXES) and values:
        raise ValueError(f"'{path.name}' is a GIfTI label file, which holds labels only, but "
                         f"{plural(len(values), 'array is', 'arrays are')} values "
                         f"({', '.join(values)}): write them to a .func.gii")
    iinfo = np.iinfo(np.int32)
    for k, v in arrays.items():
        outside = int(np.count_nonzero((v < iinfo.min) | (v > iinfo.max))) if _is_label(v) else 0
        if outside:
            are = "is" if outside == 1 else "are"
            raise ValueError(f"{plural(outside, 'label')} of '{k}' {are} outside the int32 range "
                             f"GIfTI stores (first: {v[(v < iinfo.min) | (v > iinfo.max)][0]}); "
                             "write them to a .npz (int64) or renumber them")
    darrays = [GiftiDataArray(v.astype(np.int32), intent="NIFTI_INTENT_LABEL",
                              datatype="NIFTI_TYPE_INT32", meta=GiftiMetaData({"Name": k}))
               if _is_label(v) else
               GiftiDataArray(v.astype(np.float32), intent="NIFTI_INTENT_NONE",
                              datatype="NIFTI_TYPE_FLOAT32", meta=GiftiMetaData({"Name": k}))
               for k, v in arrays.items()]
    meta = GiftiMetaData({k: str(v) for k, v in (metadata or {}).items()})
    img = GiftiImage(darrays=darrays, meta=meta)
    present = np.unique(np.concatenate([v for v in arrays.values() if _is_label(v)]
                                       or [np.zeros(0, np.int64)]))
    if len(present):
        img.labeltable = _label_table({**_default_table(present), **(label_table or {})})
    with atomic_path(path) as tmp:
        nib.save(img, str(tmp))


def _default_table(keys):
    """An entry per label: its number as name, hues spread by the golden ratio (0: grey)."""
    return {int(k): (str(int(k)), (0.5, 0.5, 0.5, 1.0) if k == 0 else
                     colorsys.hsv_to_rgb((0.618033988749895 * int(k)) % 1.0, 0.65, 0.9) + (1.0,))
            for k in keys}


def _label_table(table):
    from nibabel.gifti import GiftiLabel, GiftiLabelTable

    out = GiftiLabelTable()
    for key, (name, rgba) in sorted(table.items()):
        out.labels.append(GiftiLabel(int(key), *map(float, rgba)))
        out.labels[-1].label = str(name)
    return out

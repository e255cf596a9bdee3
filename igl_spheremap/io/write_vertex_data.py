"""Write named per-vertex arrays as NumPy ``.npz`` or GIfTI ``.func.gii``."""

from pathlib import Path

import numpy as np

from .atomic import atomic_path
from .mesh_format import GIFTI_SUFFIXES


def write_vertex_data(path, data, *, metadata=None):
    """Write per-vertex arrays, atomically; format from the name of ``path``.

    * ``*.gii`` (``.func.gii``, ``.shape.gii``; ``.gii.gz`` gzip-compressed): one GIfTI
      data array per entry,
      float32, ``NIFTI_INTENT_NONE``, its key in the array's ``Name`` metadata,
      in the order of ``data`` (loadable in FreeSurfer's freeview, Connectome
      Workbench and nibabel).
    * ``*.npz``: ``numpy.savez_compressed`` with the keys of ``data``, dtypes kept.

    Parameters
    ----------
    path : str or os.PathLike
    data : dict of str -> (n,) array
        All arrays must have the same length ``n`` (the vertex count).
    metadata : dict, optional
        GIfTI only: file-level metadata (e.g. ``AnatomicalStructurePrimary``).

    Raises
    ------
    ValueError
        Arrays of different lengths or not 1-D, or an extension other than
        ``.gii`` / ``.gii.gz`` / ``.npz``.
    """
    path = Path(path)
    arrays = {k: np.asarray(v) for k, v in data.items()}
    sizes = {v.shape for v in arrays.values()}
    if len(sizes) != 1 or len(next(iter(sizes))) != 1:
        raise ValueError(f"per-vertex arrays must be 1-D and of one length; got shapes {sizes}")
    name = path.name.lower()
    if name.endswith(GIFTI_SUFFIXES):
        import nibabel as nib
        from nibabel.gifti import GiftiDataArray, GiftiImage, GiftiMetaData

        darrays = [GiftiDataArray(v.astype(np.float32), intent="NIFTI_INTENT_NONE",
                                  datatype="NIFTI_TYPE_FLOAT32",
                                  meta=GiftiMetaData({"Name": k}))
                   for k, v in arrays.items()]
        meta = GiftiMetaData({k: str(v) for k, v in (metadata or {}).items()})
        with atomic_path(path) as tmp:
            nib.save(GiftiImage(darrays=darrays, meta=meta), str(tmp))
    elif name.endswith(".npz"):
        with atomic_path(path) as tmp:
            with open(tmp, "wb") as fh:  # a file object keeps savez from appending ".npz"
                np.savez_compressed(fh, **arrays)
    else:
        raise ValueError("per-vertex data goes to a .func.gii/.shape.gii (or .gii.gz) or .npz "
                         f"file, not '{path.name}'")

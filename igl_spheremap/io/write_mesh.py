"""Write a triangle mesh as a libigl, GIfTI or FreeSurfer file, atomically."""

from pathlib import Path

import numpy as np

from ._atomic import atomic_path
from ._stderr import captured_stderr_fd, one_line
from .mesh_format import mesh_format


def write_mesh(path, V, F, *, family=None, metadata=None):
    """Write ``(V, F)`` to ``path`` in the given format family.

    The file appears under its final name only when complete (temporary sibling
    + ``os.replace``).

    * ``"mesh"``: ``igl.write_triangle_mesh`` (format from the extension: obj,
      off, ply, stl, wrl, mesh; ASCII), double precision.
    * ``"gifti"``: a GIfTI surface (``.surf.gii``) with a ``NIFTI_INTENT_POINTSET``
      float32 array and a ``NIFTI_INTENT_TRIANGLE`` int32 array, written by nibabel.
    * ``"freesurfer"``: a FreeSurfer triangle surface written by
      ``nibabel.freesurfer.write_geometry`` (big-endian float32 / int32).

    Parameters
    ----------
    path : str or os.PathLike
        Destination; its parent directory must exist.
    V : (n, 3) float array
    F : (m, 3) int array
    family : {"mesh", "gifti", "freesurfer"}, optional
        Default: :func:`igl_spheremap.io.mesh_format` of ``path``.
    metadata : dict, optional
        ``"gifti_meta"``: metadata for the GIfTI pointset array (e.g.
        ``AnatomicalStructurePrimary``, ``GeometricType``); ``"volume_info"``:
        FreeSurfer volume geometry to append to the surface;
        ``"create_stamp"``: FreeSurfer comment line.  Ignored by other families.

    Raises
    ------
    ValueError
        Unknown family or a libigl write failure (message includes libigl's
        own diagnostic).
    """
    path = Path(path)
    family = family or mesh_format(path, must_exist=False)
    metadata = metadata or {}
    V = np.ascontiguousarray(V, dtype=np.float64)
    F = np.ascontiguousarray(F, dtype=np.int64)
    with atomic_path(path) as tmp:
        if family == "mesh":
            import igl

            err = []
            try:
                with captured_stderr_fd(err):
                    igl.write_triangle_mesh(str(tmp), V, F)
            except RuntimeError as exc:
                detail = one_line("".join(err)).replace(tmp.name, path.name)
                raise ValueError(f"cannot write '{path}': libigl could not write this format"
                                 + (f" ({detail})" if detail else f" ({exc})")) from None
        elif family == "gifti":
            import nibabel as nib
            from nibabel.gifti import GiftiDataArray, GiftiImage, GiftiMetaData

            meta = {k: str(v) for k, v in metadata.get("gifti_meta", {}).items()}
            pts = GiftiDataArray(V.astype(np.float32), intent="NIFTI_INTENT_POINTSET",
                                 datatype="NIFTI_TYPE_FLOAT32", meta=GiftiMetaData(meta))
            tri = GiftiDataArray(F.astype(np.int32), intent="NIFTI_INTENT_TRIANGLE",
                                 datatype="NIFTI_TYPE_INT32")
            nib.save(GiftiImage(darrays=[pts, tri]), str(tmp))
        elif family == "freesurfer":
            import nibabel.freesurfer as fs

            stamp = metadata.get("create_stamp", "created by igl-spheremap")
            fs.write_geometry(str(tmp), V, F, create_stamp=stamp,
                              volume_info=metadata.get("volume_info") or None)
        else:
            raise ValueError(f"cannot tell which format to write '{path}' in "
                             f"(family={family!r}); use an extension such as .obj, .off, .ply, "
                             ".stl, .surf.gii or a FreeSurfer name such as lh.sphere")

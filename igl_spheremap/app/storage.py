"""How a map is stored: the radius and precision of the written sphere, and its metadata."""

from pathlib import Path

import numpy as np

from ..io import STORED_PRECISION, stored_precision
from ..options import map_options

#: Radius of the spheres written in the neuroimaging formats (GIfTI, FreeSurfer):
#: FreeSurfer's ``?h.sphere`` and the HCP's ``*.sphere.*.surf.gii`` have radius
#: 100 (mm).  Spheres in the mesh formats (OBJ, OFF, PLY) are unit spheres.
NEURO_RADIUS = 100.0


def default_radius(family):
    """Radius of a written sphere: :data:`NEURO_RADIUS` for GIfTI and FreeSurfer, else 1."""
    return NEURO_RADIUS if family in ("gifti", "freesurfer") else 1.0


def storage_options(options, sphere, family, file_precision=None):
    """The options of a map written to ``sphere``: ``precision`` follows the file unless given.

    When ``precision`` is not given explicitly and the sphere is stored as float32
    (GIfTI by default, FreeSurfer; :data:`igl_spheremap.io.STORED_PRECISION`, or
    ``file_precision``), the map is made with ``precision="float32"`` so that the
    file is fold-free too; else ``"float64"``.  A method without the fold barrier
    (``fold_barrier=False``, e.g. ``method="paper"``) keeps ``"float64"``: the
    margin needs the barrier.

    Parameters
    ----------
    options : MapOptions or dict or None
    sphere : str or os.PathLike
        Path of the sphere file (its extension names the mesh format).
    family : {"mesh", "gifti", "freesurfer"}
    file_precision : {None, "float32", "float64"}, optional
        As in :func:`map_file`.

    Returns
    -------
    MapOptions
    """
    opts = map_options(options)
    if "precision" in opts.explicit or not opts.fold_barrier:
        return opts
    key = Path(sphere).suffix.lower() if family == "mesh" else family
    stored = file_precision or STORED_PRECISION.get(key)
    return opts.updated(precision="float32" if stored == "float32" else "float64")


def check_storage(sphere, family, radius, file_precision=None):
    """Refuse, before the map, a sphere file that could not store the map at ``radius``.

    Parameters
    ----------
    sphere : str or os.PathLike
    family : {"mesh", "gifti", "freesurfer"}
    radius : float
        Radius of the written sphere (> 0).
    file_precision : {None, "float32", "float64"}, optional
        As in :func:`igl_spheremap.app.map_file.map_file`.

    Raises
    ------
    ValueError
        The format does not store ``file_precision``
        (:func:`igl_spheremap.io.stored_precision`), or it stores float32 and
        ``radius`` is beyond float32's range (every coordinate would be stored
        as an infinity).
    """
    stored = stored_precision(sphere, file_precision, family)
    limit = float(np.finfo(np.float32).max)
    if stored == "float32" and not radius <= limit:
        raise ValueError(f"cannot write '{sphere}' at radius {radius:g}: it stores float32 "
                         f"coordinates, at most {limit:.3g}; use a smaller --radius")


HEMISPHERES = {"lh": "CortexLeft", "rh": "CortexRight"}


def output_metadata(input_path, in_family, in_meta, out_family):
    """Metadata of the written sphere and of its per-vertex data.

    Parameters
    ----------
    input_path : str or os.PathLike
        The input (``lh.*`` / ``rh.*`` names give the hemisphere).
    in_family, out_family : {"mesh", "gifti", "freesurfer"}
    in_meta : dict
        The input's metadata as :func:`igl_spheremap.io.read_mesh` returns it.

    Returns
    -------
    meta, data_meta : dict
        For :func:`igl_spheremap.io.write_mesh` and
        :func:`igl_spheremap.io.write_vertex_data`.
    """
    hemi = HEMISPHERES.get(Path(input_path).name[:2].lower()) \
        if Path(input_path).name[2:3] == "." else None
    meta = {"create_stamp": f"created by igl-spheremap from {Path(input_path).name}"}
    if out_family == "gifti":
        gmeta = dict(in_meta.get("gifti_meta", {}))
        if hemi and "AnatomicalStructurePrimary" not in gmeta:
            gmeta["AnatomicalStructurePrimary"] = hemi
        gmeta["GeometricType"] = "Spherical"
        meta["gifti_meta"] = gmeta
    if out_family == "freesurfer" and in_family == "freesurfer":
        meta["volume_info"] = in_meta.get("volume_info")
    data_meta = {}
    structure = meta.get("gifti_meta", {}).get("AnatomicalStructurePrimary", hemi)
    if structure:
        data_meta["AnatomicalStructurePrimary"] = structure
    return meta, data_meta



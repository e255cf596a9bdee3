"""How a map is stored: the radius and precision of the written sphere, and its metadata."""

import re
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
        (:func:`igl_spheremap.io.stored_precision`), or ``radius`` is outside the
        normal range of the precision it stores (float32 or float64): above it every
        coordinate would be stored as an infinity, below it as a subnormal number or
        zero, without the digits that keep the image triangles' orientation.
    """
    stored = stored_precision(sphere, file_precision, family)
    info = np.finfo(np.float32 if stored == "float32" else np.float64)
    low, high = float(info.tiny), float(info.max)
    if not low <= radius <= high:
        raise ValueError(f"cannot write '{sphere}' at radius {radius:g}: it stores {stored} "
                         f"coordinates, from {low:.3g} to {high:.3g}; use a --radius in that range")


#: GIfTI's names of the hemispheres (``AnatomicalStructurePrimary``).
HEMISPHERES = {"left": "CortexLeft", "right": "CortexRight"}

#: How file names say which hemisphere: FreeSurfer (``lh.white``), BIDS
#: (``sub-01_hemi-L_white.surf.gii``) and HCP (``100307.L.midthickness.32k_fs_LR.surf.gii``).
_HEMISPHERE_NAMES = ((re.compile(r"^lh\.", re.I), "left"), (re.compile(r"^rh\.", re.I), "right"),
                     (re.compile(r"(^|_)hemi-L(_|\.)"), "left"),
                     (re.compile(r"(^|_)hemi-R(_|\.)"), "right"),
                     (re.compile(r"\.L\."), "left"), (re.compile(r"\.R\."), "right"))

#: GIfTI metadata of the input surface that does not describe its sphere.
_NOT_OF_THE_SPHERE = ("AnatomicalStructureSecondary", "UniqueID", "Name", "GeometricType")

#: FreeSurfer's volume geometry as its GIfTI writer stores it, and as nibabel's
#: ``volume_info`` holds it.
_VOLUME_KEYS = {"volume": ("VolGeomWidth", "VolGeomHeight", "VolGeomDepth"),
                "voxelsize": ("VolGeomXsize", "VolGeomYsize", "VolGeomZsize"),
                "xras": ("VolGeomX_R", "VolGeomX_A", "VolGeomX_S"),
                "yras": ("VolGeomY_R", "VolGeomY_A", "VolGeomY_S"),
                "zras": ("VolGeomZ_R", "VolGeomZ_A", "VolGeomZ_S"),
                "cras": ("VolGeomC_R", "VolGeomC_A", "VolGeomC_S")}


def hemisphere_of(path):
    """``"left"``, ``"right"`` or None, from the file name's FreeSurfer, BIDS or HCP convention."""
    name = Path(path).name
    for pattern, side in _HEMISPHERE_NAMES:
        if pattern.search(name):
            return side
    return None


def volume_info_from_gifti(meta):
    """nibabel's FreeSurfer ``volume_info`` from the ``VolGeom*`` GIfTI metadata, or None.

    FreeSurfer's GIfTI writer (``mris_convert``) keeps the surface's volume
    geometry in the pointset's metadata; None when any of it is missing.
    """
    from collections import OrderedDict

    try:
        info = OrderedDict(head=np.array([2, 0, 20], dtype=np.int32),
                           valid="1  # volume info valid", filename=meta.get("VolGeomFname", ""))
        for key, names in _VOLUME_KEYS.items():
            dtype = np.int64 if key == "volume" else np.float64
            info[key] = np.array([float(meta[n]) for n in names]).astype(dtype)
    except (KeyError, ValueError):
        return None
    return info


def output_metadata(input_path, in_family, in_meta, out_family, hemisphere=None):
    """Metadata of the written sphere and of its per-vertex data.

    GIfTI spheres get ``GeometricType=Spherical``, the hemisphere as
    ``AnatomicalStructurePrimary`` (``hemisphere``, else the input's, else the
    file name's: :func:`hemisphere_of`) and ``TopologicalType=Closed`` on the
    triangles; what describes the input surface only (its name, unique ID,
    secondary structure) is not copied.  FreeSurfer spheres get the input's
    volume geometry, from a FreeSurfer input or from a GIfTI one's ``VolGeom*``
    metadata (:func:`volume_info_from_gifti`).

    Parameters
    ----------
    input_path : str or os.PathLike
    in_family, out_family : {"mesh", "gifti", "freesurfer"}
    in_meta : dict
        The input's metadata as :func:`igl_spheremap.io.read_mesh` returns it.
    hemisphere : {None, "left", "right"}
        Overrides what the input says.

    Returns
    -------
    meta, data_meta : dict
        For :func:`igl_spheremap.io.write_mesh` and
        :func:`igl_spheremap.io.write_vertex_data`.

    Raises
    ------
    ValueError
        An unknown ``hemisphere``.
    """
    if hemisphere not in (None, "left", "right"):
        raise ValueError(f"hemisphere must be 'left' or 'right', got {hemisphere!r}")
    gin = dict(in_meta.get("gifti_meta", {}))
    side = hemisphere or hemisphere_of(input_path)
    structure = gin.get("AnatomicalStructurePrimary")
    if hemisphere or (side and not structure):
        structure = HEMISPHERES[side]
    meta = {"create_stamp": f"created by igl-spheremap from {Path(input_path).name}"}
    if out_family == "gifti":
        gmeta = {k: v for k, v in gin.items() if k not in _NOT_OF_THE_SPHERE}
        if structure:
            gmeta["AnatomicalStructurePrimary"] = structure
        meta["gifti_meta"] = {**gmeta, "GeometricType": "Spherical"}
        meta["gifti_triangle_meta"] = {"TopologicalType": "Closed"}
    if out_family == "freesurfer":
        meta["volume_info"] = (in_meta.get("volume_info") if in_family == "freesurfer"
                               else volume_info_from_gifti(gin))
    return meta, ({"AnatomicalStructurePrimary": structure} if structure else {})

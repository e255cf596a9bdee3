"""igl_spheremap: folding-free spherical conformal maps of genus-0 meshes.

Implements Lai, Wen, Yin, Gu, Lui, "Folding-Free Global Conformal Mapping for
Genus-0 Surfaces by Harmonic Energy Minimization", J Sci Comput 2014, on libigl.

Layers, each importing only the ones above it: mesh validation
(:mod:`~igl_spheremap.validation`), operators and quality measures
(:mod:`~igl_spheremap.operators`, :mod:`~igl_spheremap.metrics`), Algorithm 1
(:mod:`~igl_spheremap.algorithm1` and its pieces), the eigen-projection and
Algorithm 2 (:mod:`~igl_spheremap.eigen_projection`, :mod:`~igl_spheremap.rounds`,
:mod:`~igl_spheremap.algorithm2`), results; the applications (``map_file``,
``cli``, ``batch``, ``viz``) sit on top and are not imported here.
"""

from .errors import MeshError, SphericalMapWarning
from .options import MapOptions
from .validation import ValidatedMesh, validate_mesh
from .metrics import (angle_distortion, area_distortion, conformal_factor, count_folds,
                      folded_faces, harmonic_energy, image_centroid, signed_image_volumes)
from .mobius import mobius_center, mobius_transform
from .gauss import gauss_map
from .result import Algorithm1Result, HarmonicMapResult, Round, SphericalMapResult
from .algorithm1 import harmonic_map
from .eigen_projection import star_map
from .untangle import untangle_folds
from .algorithm2 import spherical_conformal_map
from .landmarks import landmark_map
from .p_harmonic import p_harmonic_map
from .point_location import locate_on_sphere
from .transfer import barycentric_matrix
from .resampling import Resampled, icosphere, resample
from .mobius_area import MobiusAreaCorrection, mobius_area_correction
from .registration import SurfaceMapResult, surface_map
from .io import read_mesh, write_mesh
from .spherical_coordinates import equirectangular_uv, spherical_coordinates

__version__ = "0.1.0"


def example_mesh(name="dino.obj"):
    """Path of a mesh bundled with the package (str), for examples and first runs.

    Parameters
    ----------
    name : str
        ``"dino.obj"``: the paper's Fig. 5 dinosaur (6,013 vertices; source and
        licence in the package's ``data/README.txt``).

    Returns
    -------
    str
        A file path that ``igl.read_triangle_mesh`` and :func:`read_mesh` accept.

    Raises
    ------
    FileNotFoundError
        If the package has no bundled mesh of that name.
    """
    from importlib import resources

    ref = resources.files("igl_spheremap") / "data" / name
    if not ref.is_file():
        raise FileNotFoundError(f"no bundled mesh '{name}'; the package bundles 'dino.obj'")
    return str(ref)

__all__ = [
    "example_mesh", "MeshError", "SphericalMapWarning", "MapOptions", "ValidatedMesh", "validate_mesh",
    "angle_distortion", "area_distortion", "conformal_factor", "count_folds", "folded_faces",
    "harmonic_energy", "image_centroid", "signed_image_volumes", "mobius_center",
    "mobius_transform", "gauss_map", "Algorithm1Result", "HarmonicMapResult", "Round",
    "SphericalMapResult", "harmonic_map", "star_map", "untangle_folds",
    "spherical_conformal_map", "landmark_map", "p_harmonic_map", "locate_on_sphere", "barycentric_matrix", "Resampled",
    "icosphere", "resample", "MobiusAreaCorrection", "mobius_area_correction", "SurfaceMapResult",
    "surface_map", "read_mesh",
    "write_mesh", "spherical_coordinates", "equirectangular_uv",
]

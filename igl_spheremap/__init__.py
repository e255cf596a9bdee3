"""igl_spheremap: folding-free spherical conformal maps of genus-0 meshes.

Implements Lai, Wen, Yin, Gu, Lui, "Folding-Free Global Conformal Mapping for
Genus-0 Surfaces by Harmonic Energy Minimization", J Sci Comput 2014, on libigl.
"""

from .errors import MeshError, SphericalMapWarning
from .gauss_map import gauss_map
from .harmonic_map import HarmonicMapResult, harmonic_map
from .metrics import (angle_distortion, area_distortion, conformal_factor, count_folds,
                      folded_faces, harmonic_energy, image_centroid, signed_image_volumes)
from .mobius import mobius_center, mobius_transform
from .result import Round, SphericalMapResult
from .spherical_conformal_map import spherical_conformal_map
from .star_map import star_map
from .untangle import untangle_folds
from .validation import ValidatedMesh, validate_mesh
from .io import read_mesh, write_mesh
from .spherical_coordinates import equirectangular_uv, spherical_coordinates

__version__ = "0.1.0"

__all__ = [
    "MeshError", "SphericalMapWarning", "gauss_map", "harmonic_map", "HarmonicMapResult", "angle_distortion",
    "area_distortion", "conformal_factor", "count_folds", "folded_faces", "harmonic_energy",
    "image_centroid", "signed_image_volumes", "mobius_center", "mobius_transform", "Round",
    "SphericalMapResult", "spherical_conformal_map", "star_map", "ValidatedMesh",
    "validate_mesh", "untangle_folds", "read_mesh", "write_mesh", "spherical_coordinates",
    "equirectangular_uv",
]

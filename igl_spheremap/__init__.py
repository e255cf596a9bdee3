"""igl_spheremap: folding-free spherical conformal maps of genus-0 meshes.

Implements Lai, Wen, Yin, Gu, Lui, "Folding-Free Global Conformal Mapping for
Genus-0 Surfaces by Harmonic Energy Minimization", J Sci Comput 2014, on libigl.

Subpackages follow the data path, each importing only the ones before it
(``tests/test_architecture.py`` checks the order):

1. :mod:`~igl_spheremap.mesh`: validation, topology, operators, generated shapes;
2. :mod:`~igl_spheremap.sphere`: spherical maps as such: folds and rounding
   margins, quality measures, Möbius transformations, point location, charts;
3. :mod:`~igl_spheremap.optimize`: Algorithm 1 (manifold, energies, search
   direction, step size, line search, fold barrier, gauge, ``minimize``);
4. :mod:`~igl_spheremap.folding`: Algorithm 2 (Gauss and star maps, rounds,
   untangling, local repair; the decision tree of what runs when);
5. :mod:`~igl_spheremap.precision`: the float32 repairs;
6. :mod:`~igl_spheremap.conformal_map`: the whole map, ``spherical_conformal_map``;
7. :mod:`~igl_spheremap.uses`: landmarks, maps between surfaces, atlas
   registration by features, resampling, p-harmonic maps, area correction;
8. :mod:`~igl_spheremap.io`, :mod:`~igl_spheremap.app` (the file jobs behind the
   command line), :mod:`~igl_spheremap.cli`, :mod:`~igl_spheremap.viz`.

``errors`` and ``options`` are used by every layer.  The public names are
importable from here; ``app``, ``cli`` and ``viz`` are not imported by this module.
"""

from .errors import MeshError, SphericalMapWarning
from .options import MapOptions
from .mesh.validate import ValidatedMesh, validate_mesh
from .mesh.shapes import icosphere
from .sphere.folds import count_folds, folded_faces, map_degree, signed_image_volumes
from .sphere.quality import (angle_distortion, area_distortion, conformal_factor,
                             harmonic_energy, image_centroid)
from .sphere.mobius import mobius_center, mobius_transform
from .sphere.locate import locate_on_sphere
from .sphere.transfer import barycentric_matrix
from .sphere.coordinates import equirectangular_uv, spherical_coordinates
from .optimize.result import Algorithm1Result, HarmonicMapResult
from .optimize.harmonic import harmonic_map
from .folding.result import Round, SphericalMapResult
from .folding.starts import gauss_map
from .folding.star_map import star_map
from .folding.untangle import untangle_folds
from .conformal_map import spherical_conformal_map
from .uses.landmarks import landmark_map
from .uses.p_harmonic import p_harmonic_map
from .uses.resampling import (Registration, Resampled, registration_matrices, resample,
                              resample_labels, resampling_matrix)
from .uses.atlas import AtlasRegistrationResult, Level, register_sphere
from .uses.atlas_multires import register_sphere_multires, register_surface
from .optimize.area_balanced import area_balanced_map
from .sphere.field import SphereField
from .uses.area_correction import MobiusAreaCorrection, mobius_area_correction
from .uses.registration import SurfaceMapResult, surface_map
from .io import read_mesh, write_mesh

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
    if name != "dino.obj" or not ref.is_file():  # data/ holds its README too
        raise FileNotFoundError(f"no bundled mesh '{name}'; the package bundles 'dino.obj'")
    return str(ref)

__all__ = [
    "example_mesh", "MeshError", "SphericalMapWarning", "MapOptions", "ValidatedMesh", "validate_mesh",
    "angle_distortion", "area_distortion", "conformal_factor", "count_folds", "folded_faces",
    "harmonic_energy", "image_centroid", "map_degree", "signed_image_volumes", "mobius_center",
    "mobius_transform", "gauss_map", "Algorithm1Result", "HarmonicMapResult", "Round",
    "SphericalMapResult", "harmonic_map", "star_map", "untangle_folds",
    "spherical_conformal_map", "landmark_map", "p_harmonic_map", "locate_on_sphere", "barycentric_matrix", "Resampled",
    "icosphere", "resample", "MobiusAreaCorrection", "mobius_area_correction", "SurfaceMapResult",
    "surface_map", "read_mesh", "Registration", "registration_matrices", "resample_labels",
    "resampling_matrix", "AtlasRegistrationResult", "Level", "register_sphere",
    "register_sphere_multires", "register_surface", "area_balanced_map", "SphereField",
    "write_mesh", "spherical_coordinates", "equirectangular_uv",
]

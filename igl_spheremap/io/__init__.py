"""Mesh and per-vertex data I/O: libigl formats, GIfTI and FreeSurfer surfaces (via nibabel).

Every writer here is atomic (temporary sibling file + ``os.replace``).  Maps
are written at full precision where the format allows it (OBJ, OFF, PLY;
GIfTI with ``precision="float64"``); :func:`stored_folds` counts the folds of
what a file stores.  OBJ, OFF, ASCII STL, VRML and MEDIT files are checked strictly
before libigl reads them (:func:`check_obj`, :func:`check_off`, :func:`check_stl`,
:func:`check_wrl`, :func:`check_mesh`), PLY files are read by ``plyfile``
(:func:`read_ply`) and Gmsh files by ``meshio`` (:func:`read_msh`), on which libigl's
readers can abort or hang;
:func:`check_output_paths` refuses, before any work, outputs that cannot be
written or would overwrite the input.
"""

from .check_mesh import check_mesh
from .check_obj import TextMesh, check_obj
from .check_off import check_off
from .check_stl import check_stl
from .check_wrl import check_wrl
from .check_output_paths import check_output_paths, check_outputs
from .check_sphere_output import SPHERE_FORMATS, check_sphere_output
from .file_digest import file_digest
from .mesh_format import (FREESURFER_MAGIC, IGL_EXTENSIONS, curv_layout, is_freesurfer_surface,
                          mesh_format)
from .output_paths import OutputPaths, output_paths
from .read_mesh import check_arrays, read_mesh
from .read_landmarks import read_landmarks
from .read_msh import read_msh
from .read_ply import read_ply
from .read_vertex_data import read_vertex_data, read_vertex_labels, read_vertex_mask
from .result_file import load_result, save_result
from .stored_folds import stored_folds
from .write_mesh import STORED_PRECISION, stored_precision, write_mesh
from .write_report import write_report
from .write_vertex_data import check_data_output, write_vertex_data

__all__ = ["FREESURFER_MAGIC", "IGL_EXTENSIONS", "SPHERE_FORMATS", "STORED_PRECISION", "TextMesh",
           "check_arrays", "check_data_output", "check_mesh", "check_obj", "check_off", "check_stl", "check_wrl",
           "check_output_paths", "check_outputs", "check_sphere_output", "curv_layout",
           "file_digest", "is_freesurfer_surface", "mesh_format",
           "OutputPaths", "output_paths", "read_landmarks", "read_mesh", "read_msh", "read_ply",
           "read_vertex_data", "read_vertex_labels", "read_vertex_mask", "load_result", "save_result", "stored_folds", "stored_precision",
           "write_mesh", "write_report", "write_vertex_data"]

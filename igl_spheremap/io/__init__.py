"""Mesh and per-vertex data I/O: libigl formats, GIfTI and FreeSurfer surfaces (via nibabel).

Every writer here is atomic (temporary sibling file + ``os.replace``).
"""

from .mesh_format import FREESURFER_MAGIC, IGL_EXTENSIONS, mesh_format
from .output_paths import OutputPaths, output_paths
from .read_mesh import read_mesh
from .write_mesh import write_mesh
from .write_report import write_report
from .write_vertex_data import write_vertex_data

__all__ = ["FREESURFER_MAGIC", "IGL_EXTENSIONS", "mesh_format", "OutputPaths", "output_paths",
           "read_mesh", "write_mesh", "write_report", "write_vertex_data"]

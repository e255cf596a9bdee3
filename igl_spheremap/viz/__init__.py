"""Polyscope view of Algorithm 2, stage by stage (the folding-removal demo).

``import igl_spheremap`` does not import this module, and this module imports
polyscope (and matplotlib, for the contact sheet) only inside the functions
that draw, so the core package works without a display or OpenGL.

A *stage* is one spherical map produced while :func:`spherical_conformal_map`
runs: the Gauss map, the map after Algorithm 1, then for each folding-removal
round ``k`` the star map and the map after Algorithm 1 again.  For each stage
the view shows, in one row (left to right):

1. the input surface with the faces that are folded in this stage's map in red,
2. the spherical image, folded faces in red, turned so that the folded faces
   face the viewer (no turn once nothing is folded),
3. the same spherical image turned by 180 degrees (its far side); a grey circle
   outlines the unit sphere behind both views,
4. the input surface coloured by the log conformal factor ``u`` (paper Fig. 3,
   third row; ``u = 0.5 log e^{2u}``, Eq. 14),
5. the weighted Laplace-Beltrami eigenfunctions ``Phi^u = (phi_1, phi_2, phi_3)``
   drawn as a surface scaled to unit size (paper Fig. 9, right column):
   an ellipsoid while the conformal factor is wrong, a round sphere once the
   map is conformal and folding free.

Folded image triangles are often tiny slivers, so on the sphere every folded
face is also marked by a red dot (its centroid pushed onto the sphere), and
small clusters of folded faces are circled in red.

Modules: :mod:`.stages` (the data of each stage), :mod:`.layout` (placement),
:mod:`.scene` (polyscope structures), :mod:`.viewer` (the window or the
screenshots), :mod:`.sheet` (the contact sheet), :mod:`.style`.
"""

from .scene import register_stage
from .sheet import contact_sheet
from .stages import build_stages
from .style import COLUMN_LABELS, HEADLESS_PACKAGES
from .viewer import StageView, show

__all__ = ["build_stages", "register_stage", "show", "StageView", "contact_sheet",
           "COLUMN_LABELS", "HEADLESS_PACKAGES"]

"""Polyscope view of Algorithm 2, stage by stage (the folding-removal demo).

``import igl_spheremap`` does not import this module, and this module imports
polyscope (and matplotlib, for the contact sheet) only inside the functions
that draw, so the core package works without a display or OpenGL.

A *stage* is one spherical map produced while :func:`spherical_conformal_map`
runs: the Gauss map, the map after Algorithm 1, then for each folding-removal
round ``k`` the star map and the map after Algorithm 1 again.  For each stage
the view shows, in one row (left to right):

1. the input surface painted with *part colours*: a smooth colour field
   given by the direction of each point from the centre of the input as seen
   on screen, round a colour wheel without red (head, tail, front and hind
   legs of an animal get different hues; near parts lighter, far parts
   darker); the faces folded in this stage's map are red;
2. the spherical image with the same colours, so the colour at a point of the
   sphere says which part of the input went there; turned so that the folded
   faces face the viewer (no turn once nothing is folded);
3. the same spherical image turned by 180 degrees (its far side); a grey circle
   outlines the unit sphere behind both views;
4. the input with a checkerboard of a conformal chart of the sphere (Mercator
   after a Moebius map putting two shrunk tips at the poles, see
   :func:`.fields.mercator_corners`) pulled back
   through the map: the checks are squares where the map is conformal and
   sheared or torn where it is not;
5. the input coloured by the log conformal factor ``u`` (``u = 0.5 log e^{2u}``,
   Eq. 14; paper Fig. 3, third row), purple where the sphere shrinks the
   surface, green where it grows it, white where areas are kept.

The up to eight tips of the input that the last map shrinks most (head, tail,
feet) are marked by dots in their part colour on the input and on both
spheres, and numbered in the screenshots, so a limb whose image is too small
to see still shows where it went.  Folded image triangles are often tiny
slivers, so on the sphere every folded face is also marked by a red dot (its
centroid pushed onto the sphere), and small clusters of folded faces are
circled in red.  The weighted Laplace-Beltrami eigenfunctions ``Phi^u`` (paper
Fig. 9) are not drawn (a nearly round ball for every stage after the first,
it showed nothing); their radius spread and eigenvalues are in the panel.

Each screenshot becomes an annotated PNG (title, column headers, legends and
the colour bar of ``u`` with the range used), and all stages are stacked into
a contact sheet.

Modules: :mod:`.stages` (the data of each stage), :mod:`.fields` (part colours,
checkerboard coordinates, u colours, tips), :mod:`.layout` (placement and
camera), :mod:`.scene` (polyscope structures), :mod:`.viewer` (the window or the
screenshots), :mod:`.sheet` (annotated PNGs and the contact sheet), :mod:`.style`.

The registration view (``demos/registration.py``) of an inter-surface map
(:func:`igl_spheremap.surface_map`) lives in :mod:`.registration.stages` (its
stages and the data carried), :mod:`.registration.layout`,
:mod:`.registration.scene`, :mod:`.registration.sheet` and
:mod:`.registration.view` (:func:`show_registration`).
"""

from .fields import (chart_poles, mercator_corners, mercator_vertices, part_colors,
                     tip_vertices, u_colors)
from .layout import project
from .registration.stages import build_registration_stages
from .registration.view import RegistrationView, show_registration
from .scene import register_stage
from .sheet import compose_stage, contact_sheet, stage_png_boxes
from .stages import build_stages
from .style import COLUMN_LABELS, HEADLESS_PACKAGES
from .viewer import StageView, show

__all__ = ["build_stages", "register_stage", "show", "StageView", "contact_sheet",
           "compose_stage", "stage_png_boxes", "project", "part_colors", "mercator_corners",
           "chart_poles", "mercator_vertices", "build_registration_stages", "show_registration",
           "RegistrationView", "tip_vertices", "u_colors", "COLUMN_LABELS", "HEADLESS_PACKAGES"]

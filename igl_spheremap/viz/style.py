"""Layout constants, colours and structure names of the stage view."""

import numpy as np

HEADLESS_PACKAGES = ("libegl1", "libegl-mesa0", "libgl1-mesa-dri", "libgl1", "libglx-mesa0",
                     "libx11-6")

#: Titles of the five columns of a stage view, left to right.
COLUMN_LABELS = ("input, coloured by part; folded faces red",
                 "sphere, same colours; folds face you",
                 "sphere, far side",
                 "checkerboard of the sphere on the input",
                 "u = log conformal factor")

#: Matplotlib colour map of ``u`` (purple-white-green: no red, which marks folds).
U_CMAP = "PRGn"

_SPACING = 2.7          # distance between column centres (objects have radius ~1)
COLUMN_X = _SPACING * np.arange(-2, 3)
WINDOW = (2000, 440)            # screenshots
WINDOW_INTERACTIVE = (1700, 800)
LENGTH_SCALE = 16.0
RED = np.array([0.86, 0.08, 0.08])
#: The colour wheel of the part colours: (direction in degrees from +x towards +y on
#: screen, RGB), increasing angles.  It goes gold, pale, violet, blue, teal, green and
#: back to gold without passing red (the colour of folded faces).
PART_WHEEL = ((45.0, (0.30, 0.72, 0.05)), (135.0, (1.00, 0.74, 0.00)),
               (190.0, (0.95, 0.90, 0.74)), (245.0, (0.62, 0.18, 0.95)),
               (290.0, (0.10, 0.30, 1.00)), (335.0, (0.00, 0.70, 0.74)))
CHECKER_COLORS = ((0.97, 0.96, 0.92), (0.16, 0.22, 0.34))
CHECKS_AROUND = 24     # checks round the equator of the Mercator chart (even: seamless)
MERCATOR_CLIP = 60.0     # |log|w|| beyond this only at the poles themselves
TURN = np.diag([-1.0, 1.0, -1.0])   # 180 degrees about the screen's vertical axis

NAMES = dict(input="input: parts", front="sphere (front)", back="sphere (back)",
              checker="input: Mercator checks", u="input: conformal factor u",
              dots_front="folded faces (front)", rings_front="fold clusters (front)",
              rings_back="fold clusters (back)", outline="unit sphere outline",
              dots_back="folded faces (back)")

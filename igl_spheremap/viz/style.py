"""Layout constants, colours and structure names of the stage view."""

import numpy as np

HEADLESS_PACKAGES = ("libegl1", "libegl-mesa0", "libgl1-mesa-dri", "libgl1", "libglx-mesa0",
                     "libx11-6")

#: Titles of the five columns of a stage view, left to right.
COLUMN_LABELS = ("input surface, folded faces red", "spherical image, folds facing you",
                 "spherical image, far side", "input coloured by u (log conformal factor)",
                 "Φ^u = (φ1, φ2, φ3), centred, unit size")

_SPACING = 2.7          # distance between column centres (objects have radius ~1)
_COLUMN_X = _SPACING * np.arange(-2, 3)
_WINDOW = (2000, 440)            # screenshots
_WINDOW_INTERACTIVE = (1700, 800)
_LENGTH_SCALE = 16.0
_RED = np.array([0.86, 0.08, 0.08])
_INPUT_COLOR = np.array([0.80, 0.78, 0.72])
_SPHERE_COLOR = np.array([0.62, 0.74, 0.88])
_PHI_COLOR = np.array([0.93, 0.70, 0.40])
_TURN = np.diag([-1.0, 1.0, -1.0])   # 180 degrees about the screen's vertical axis

_NAMES = dict(input="input: folded faces", front="sphere (front)", back="sphere (back)",
              u="input: conformal factor u", phi="Phi^u (unit size)",
              dots_front="folded faces (front)", rings_front="fold clusters (front)",
              rings_back="fold clusters (back)", outline="unit sphere outline",
              dots_back="folded faces (back)")

"""Aligning surface 1's conformal spherical map to surface 2's before they are put in correspondence.

* With three or more landmark pairs: the Möbius transformation that best fits
  surface 1's landmark images to surface 2's
  (:func:`igl_spheremap.sphere.mobius.mobius_fit`), its translation halved while
  it folds faces (a Möbius transformation can flip large flat image triangles).
* With fewer: both maps are Möbius-centred by area
  (:func:`igl_spheremap.sphere.mobius.mobius_center`), which leaves a rotation to
  find (Baden, Crane, Kazhdan, "Möbius Registration", SGP 2018), and the
  rotations that best correlate the two log conformal factors on the sphere
  are found over all of SO(3) by spherical harmonics
  (:func:`igl_spheremap.sphere.harmonics.best_rotations`).  The log conformal
  factor is intrinsic (it depends on the metric only), so poses of one body
  have nearly the same one.  Several hypotheses are returned: the caller
  refines each and keeps the one with the least distortion.  The best
  correlation over improper rotations (the mirror image) is reported too.
"""

from dataclasses import dataclass

import numpy as np

from ..mesh.operators import vertex_areas
from ..sphere.folds import count_folds
from ..sphere.harmonics import MIRROR, best_rotations, sample_grid, sh_coefficients
from ..sphere.locate import locate_on_sphere
from ..sphere.mobius import mobius_center, mobius_fit, mobius_transform
from ..sphere.quality import conformal_factor

#: Degree of the spherical harmonic expansions of the rotation search.
SH_DEGREE = 12

#: Rotation hypotheses the search returns (local maxima of the correlation).
HYPOTHESES = 4

#: Largest number of halvings of the Möbius fit's translation while it folds faces.
MAX_SHRINKS = 10


@dataclass
class Start:
    """One aligned start of surface 1's map.

    Attributes
    ----------
    U : (n1, 3) float64 array
        Surface 1's map (validated order), fold-free.
    label : str
        How it was aligned (for messages).
    score : float or None
        Normalized correlation of the log conformal factors (rotation search), in [-1, 1].
    """

    U: np.ndarray
    label: str
    score: float = None


def landmark_start(F1, U1, lm1, targets):
    """Surface 1's map moved by the Möbius transformation that best fits its landmarks to ``targets``.

    Parameters
    ----------
    F1 : (m1, 3) int64 array
    U1 : (n1, 3) float64 array
        Fold-free map.
    lm1 : (k,) int64 array
        Landmark vertices, ``k >= 3``.
    targets : (k, 3) float64 array
        Unit vectors.

    Returns
    -------
    Start
    """
    c, R, res = mobius_fit(U1[lm1], targets)
    shrink = 1.0
    Y = mobius_transform(U1, c) @ R.T
    while count_folds(F1, Y) and shrink > 2.0 ** -MAX_SHRINKS:
        shrink *= 0.5
        Y = mobius_transform(U1, c * shrink) @ R.T
    if count_folds(F1, Y):
        shrink, Y = 0.0, U1 @ mobius_fit(U1[lm1][:2], targets[:2])[1].T
    label = f"Möbius fit to {lm1.size} landmarks (chordal RMS residual {res:.3g})"
    if shrink < 1.0:
        label += f", its translation scaled by {shrink:g} to keep the map fold-free"
    return Start(U=Y, label=label)


def centred(V, F, U):
    """``U`` Möbius-centred with the vertex areas of ``(V, F)`` ((n, 3) float64)."""
    return mobius_center(U, vertex_areas(V, F))[0]


def log_conformal_samples(V, F, U, degree=SH_DEGREE):
    """Spherical harmonic coefficients of the standardized log conformal factor of the map ``U``.

    The per-vertex ``u = log(e^{2u}) / 2`` (:func:`igl_spheremap.sphere.quality.conformal_factor`)
    is interpolated at the directions of :func:`igl_spheremap.sphere.harmonics.sample_grid`
    (:func:`igl_spheremap.sphere.locate.locate_on_sphere`), shifted and scaled to mean 0 and
    variance 1 over the sphere, and expanded.
    """
    u = 0.5 * np.log(np.maximum(conformal_factor(V, F, U), 1e-300))
    X, theta, w = sample_grid(degree)
    face, bary = locate_on_sphere(U, F, X.reshape(-1, 3))
    s = np.einsum("ij,ij->i", u[F[face]], bary).reshape(X.shape[:2])
    wq = np.repeat(w[:, None], s.shape[1], axis=1)
    mean = float(np.sum(wq * s) / np.sum(wq))
    sd = float(np.sqrt(np.sum(wq * (s - mean) ** 2) / np.sum(wq)))
    return sh_coefficients((s - mean) / max(sd, 1e-300), theta, w, degree)


def rotation_starts(V1, F1, U1, V2, F2, U2, count=HYPOTHESES, degree=SH_DEGREE):
    """Rotations of surface 1's area-centred map that best correlate the log conformal factors.

    Parameters
    ----------
    V1, F1, U1, V2, F2, U2 : arrays
        The two surfaces and their fold-free maps (validated order), both
        Möbius-centred by area (:func:`centred`).
    count : int
        Hypotheses returned.
    degree : int
        Of the spherical harmonic expansions.

    Returns
    -------
    starts : list of Start
        Best correlation first; ``U @ R`` for a rotation ``R`` each.
    mirror : float
        Best normalized correlation over improper rotations (surface 1's mirror
        image; not a candidate: both surfaces are oriented outward, so an
        orientation-reversing correspondence would fold every face).
    """
    f1 = log_conformal_samples(V1, F1, U1, degree)
    f2 = log_conformal_samples(V2, F2, U2, degree)
    norm = 4.0 * np.pi  # the correlation of a standardized function with itself
    found = best_rotations(f2, f1, count)
    starts = [Start(U=U1 @ R.T, score=c / norm,
                    label=f"area-centred, rotated by log-conformal-factor correlation "
                          f"{c / norm:.3f}") for c, R in found]
    f1m = log_conformal_samples(V1, F1[:, ::-1], U1 @ MIRROR, degree)  # reflected, reoriented
    mirror = best_rotations(f2, f1m, 1)[0][0] / norm
    return starts, float(mirror)

"""Per-vertex features on spherical meshes: heat smoothing, standardization, weighted correlation.

The features of an atlas registration (sulcal depth, curvature) are compared
at several scales (:mod:`igl_spheremap.uses.atlas`): both sides are smoothed
on their spheres by heat diffusion and standardized with their spheres' vertex
areas, and matches are scored by area-weighted correlations.
"""

import numpy as np
import scipy.sparse as sp

from ..errors import plural
from ..mesh.operators import laplacian, vertex_areas
from ..optimize.preconditioner import h1_preconditioner


def heat_smooth(U, F, values, fwhm, steps=4, L=None, area=None):
    """Smooth per-vertex data on a spherical mesh by heat diffusion.

    ``steps`` implicit Euler steps of ``du/dt = Delta u`` on the mesh, for a
    total time ``t = fwhm^2 / (16 ln 2)`` (the Gaussian of that full width at
    half maximum in the plane has variance ``2 t``).

    Parameters
    ----------
    U : (n, 3) float array
        Unit vectors (the mesh's sphere; lengths are radians of arc).
    F : (m, 3) int array
    values : (n,) or (n, d) float array
    fwhm : float
        Full width at half maximum, radians on the unit sphere; 0 returns a copy.
    steps : int
    L, area : optional
        Precomputed intrinsic Delaunay Laplacian and vertex areas of ``(U, F)``.

    Returns
    -------
    (n,) or (n, d) float64 array
    """
    f = np.array(values, dtype=np.float64)
    if fwhm <= 0:
        return f
    L = laplacian(U, F) if L is None else L
    area = vertex_areas(U, F) if area is None else area
    t = fwhm * fwhm / (16.0 * np.log(2.0))
    M = sp.diags(area)
    solve = h1_preconditioner((M - (t / steps) * L).tocsc(), "direct")
    for _ in range(steps):
        f = solve(M @ f)
    return f


def standardized(values, area):
    """``(values - mean) / sd`` per column, area weighted ((n,) or (n, d) float64)."""
    f = np.asarray(values, dtype=np.float64)
    w = area / area.sum()
    mean = w @ f
    sd = np.sqrt(w @ (f - mean) ** 2)
    return (f - mean) / np.where(sd > 0, sd, 1.0)


def weighted_correlation(a, b, w):
    """Per column, the ``w``-weighted Pearson correlation of ``a`` and ``b`` ((n,) or (n, d)).

    Returns
    -------
    (d,) float64 array
    """
    a2 = np.asarray(a, dtype=np.float64).reshape(len(a), -1)
    b2 = np.asarray(b, dtype=np.float64).reshape(len(b), -1)
    w = np.asarray(w, dtype=np.float64) / np.sum(w)
    a2 = a2 - w @ a2
    b2 = b2 - w @ b2
    return (w @ (a2 * b2)) / np.sqrt((w @ a2 ** 2) * (w @ b2 ** 2))


def constant_columns(x, name):
    """A ValueError's message when a column of the features ``x`` ((n, d)) does not vary,
    else None (names ``name``, the count and the first such column: a feature that does not
    vary cannot be matched, and its correlation is undefined)."""
    x = np.asarray(x, dtype=np.float64).reshape(len(x), -1)
    flat = np.flatnonzero(np.ptp(x, axis=0) == 0)
    if not flat.size:
        return None
    return (f"{flat.size} of the {x.shape[1]} columns of {name} are constant (first: column "
            f"{flat[0]}, value {x[0, flat[0]]:g}): a feature that does not vary cannot be matched")


def unmatched_columns(subject, target):
    """A ValueError's message when the subject's and the target's features ((n, d), (k, e))
    have different column counts, else None: the registration matches column to column."""
    d, e = (np.shape(x)[1] if np.ndim(x) == 2 else 1 for x in (subject, target))
    if d == e:
        return None
    return (f"{plural(d, 'subject feature')} but {plural(e, 'target feature')}; give the same "
            "kinds in the same columns")

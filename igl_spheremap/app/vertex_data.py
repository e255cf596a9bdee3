"""Per-vertex quantities of a spherical map, as written by the CLI's ``--data``."""

import numpy as np

from ..sphere.coordinates import equirectangular_uv, spherical_coordinates
from ..sphere.folds import folded_faces
from ..sphere.quality import conformal_factor


def vertex_data(V, F, U):
    """Per-vertex data of the map ``U`` of ``(V, F)``, keyed by the names used in files.

    Parameters
    ----------
    V : (n, 3) float64 array
        Input vertices.
    F : (m, 3) int array
        Faces oriented outward (as :func:`igl_spheremap.validate_mesh` returns
        them, re-indexed to ``V``), so that :func:`igl_spheremap.folded_faces`
        is meaningful.
    U : (n, 3) float64 array
        The spherical map (unit rows).

    Returns
    -------
    dict of str -> (n,) array, in this order:
        ``log_conformal_factor``
            ``u = 0.5 * log(e^{2u})`` from :func:`igl_spheremap.conformal_factor`
            (paper Eq. 14, input scaled to area ``4 pi``): 0 where the map keeps
            area, negative where it shrinks.  NaN for vertices in no face.
        ``theta``, ``phi``
            Polar angle ``[0, pi]`` and azimuth ``[-pi, pi)`` of ``U``, radians
            (:func:`igl_spheremap.spherical_coordinates`).
        ``tex_u``, ``tex_v``
            Equirectangular texture coordinates in ``[0, 1]``
            (:func:`igl_spheremap.equirectangular_uv`).
        ``folded``
            bool: the vertex belongs to at least one folded face of ``U``.
    """
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    U = np.asarray(U, dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        u = 0.5 * np.log(conformal_factor(V, F, U))
    theta, phi = spherical_coordinates(U)
    uv = equirectangular_uv(U)
    folded = np.zeros(len(U), dtype=bool)
    folded[F[folded_faces(F, U)].ravel()] = True
    return {"log_conformal_factor": u, "theta": theta, "phi": phi,
            "tex_u": uv[:, 0], "tex_v": uv[:, 1], "folded": folded}

"""The distortion of a map between two surfaces, per face: how far each triangle of surface 1 is
from an isometry onto its image (``SurfaceMapResult.distortion``, the registration demo's colours)."""

import numpy as np

from ..mesh.frames import triangle_frames


def face_distortion(V1, F1, X):
    """Per-face symmetric Dirichlet distortion of the piecewise-linear map ``V1 -> X`` ((m,) float64).

    ``(s1^2 + s2^2 + s1^-2 + s2^-2) / 4`` of the singular values of each
    triangle's Jacobian: 1 for an isometry, infinite for a degenerate image
    (Smith, Schaefer, "Bijective parameterization with free boundaries", TOG 2015).
    Both meshes should be at the same scale (e.g. area ``4 pi``).

    Parameters
    ----------
    V1 : (n, 3) float64 array
    F1 : (m, 3) int64 array
        Surface 1.
    X : (n, 3) float64 array
        The image of each vertex of surface 1 (e.g. its place on surface 2).

    Returns
    -------
    (m,) float64 array
        At least 1 (dimensionless).
    """
    _, Dinv, _ = triangle_frames(V1, F1)
    E = np.stack([X[F1[:, 1]] - X[F1[:, 0]], X[F1[:, 2]] - X[F1[:, 0]]], axis=2)
    s = np.maximum(np.linalg.svd(E @ Dinv, compute_uv=False), 1e-300)
    return 0.25 * (s ** 2 + s ** -2).sum(axis=1)

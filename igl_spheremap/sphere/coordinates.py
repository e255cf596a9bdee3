"""Spherical angles of points on the sphere, their inverse, and equirectangular texture coordinates.

The three functions are one convention and are kept together:
polar angle ``theta`` from the +z axis, in ``[0, pi]``; azimuth ``phi`` from
the +x axis towards +y, in ``[-pi, pi)``; all in radians.
"""

import numpy as np

from ..mesh.arrays import as_points


def spherical_coordinates(U):
    """Polar and azimuthal angles of the directions ``U``.

    ``theta = atan2(sqrt(x^2 + y^2), z)`` (equal to ``arccos(z / |U|)`` but
    accurate near the poles) and ``phi = atan2(y, x)``, with ``phi = pi``
    mapped to ``-pi`` so that ``phi`` lies in ``[-pi, pi)``.  Rows need not be
    unit: only their direction counts (a zero row gives ``theta = phi = 0``).

    Parameters
    ----------
    U : (n, 3) float array

    Returns
    -------
    theta : (n,) float64 array
        Polar angle in radians, ``[0, pi]``; 0 at the north pole ``(0, 0, 1)``.
    phi : (n,) float64 array
        Azimuth in radians, ``[-pi, pi)``; 0 on the +x half-plane.

    Raises
    ------
    ValueError
        ``U`` is not (n, 3) finite numbers.
    """
    U = as_points(U, "U")
    x, y, z = U[:, 0], U[:, 1], U[:, 2]
    theta = np.arctan2(np.hypot(x, y), z)
    phi = np.arctan2(y, x)
    phi = np.where(phi >= np.pi, phi - 2.0 * np.pi, phi)
    return theta, phi


def spherical_to_cartesian(theta, phi, radius=1.0):
    """Points of the sphere of the given radius at angles ``(theta, phi)``.

    Inverse of :func:`spherical_coordinates`:
    ``(r sin(theta) cos(phi), r sin(theta) sin(phi), r cos(theta))``.

    Parameters
    ----------
    theta, phi : (n,) float arrays
        Radians (polar angle from +z, azimuth from +x).
    radius : float, default 1.0

    Returns
    -------
    (n, 3) float64 array
    """
    theta = np.asarray(theta, dtype=np.float64)
    phi = np.asarray(phi, dtype=np.float64)
    s = np.sin(theta)
    return radius * np.column_stack([s * np.cos(phi), s * np.sin(phi), np.cos(theta)])


def equirectangular_uv(U):
    """Equirectangular (latitude-longitude) texture coordinates of directions ``U``.

    ``u = (phi + pi) / (2 pi)`` in ``[0, 1)`` (``u = 0`` at ``phi = -pi``, the -x
    half-plane) and ``v = 1 - theta / pi`` in ``[0, 1]`` (``v = 1`` at the north
    pole, the usual image-up convention of OpenGL-style texture coordinates).
    Faces crossing the ``phi = +-pi`` seam get coordinates from both image edges;
    cut the mesh along the seam for seamless texturing.

    Parameters
    ----------
    U : (n, 3) float array

    Returns
    -------
    (n, 2) float64 array
        Columns ``u``, ``v``.

    Raises
    ------
    ValueError
        As :func:`spherical_coordinates`.
    """
    theta, phi = spherical_coordinates(U)
    return np.column_stack([(phi + np.pi) / (2.0 * np.pi), 1.0 - theta / np.pi])

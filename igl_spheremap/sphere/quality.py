"""Quality measures of a spherical map ``U`` of a mesh ``(V, F)``: harmonic energy, conformal
factor, angle and area distortion, image centroid.

Every function here works on the input ``(V, F)`` and the image ``U`` as
given (it checks their shapes, finiteness and index ranges, but does not
validate or reorient the mesh: pass outward-oriented faces, e.g. ``result.F``).
The measures do not depend on the units of ``V``, so each takes ``V`` times the
power of two that brings its bounding-box diagonal into [1, 2) (exact, as
:func:`igl_spheremap.validate_mesh` does): coordinates near 1e-300 or 1e300, which
the map itself handles, would under- or overflow in squared edge lengths.  The
conformal factor and the image centroid are measures of a map onto the *unit*
sphere and refuse a ``U`` off it (:func:`igl_spheremap.mesh.arrays.off_unit_sphere`);
angle and area distortion do not depend on its radius, and the harmonic energy is
the Dirichlet energy of any ``U``.
"""

import igl
import numpy as np

from ..mesh.arrays import as_map_of, off_unit_sphere
from ..mesh.operators import dirichlet_energy, to_sphere_area, vertex_areas
from ..mesh.validate import power_of_two_scaled


def _unitless(V, F, U, unit=False):
    """:func:`as_map_of`'s arrays with ``V`` scaled by a power of two to a diagonal in [1, 2);
    with ``unit``, a ``U`` with rows off the unit sphere is refused (the measures of a map
    onto the unit sphere whose value scales with its radius)."""
    V, F, U = as_map_of(V, F, U)
    off = off_unit_sphere(U) if unit else None
    if off:
        raise ValueError(off)
    return power_of_two_scaled(V, np.ones(V.shape[0], dtype=bool))[0], F, U


def harmonic_energy(V, F, U, L=None):
    """Discrete harmonic (Dirichlet) energy of paper Eq. 6 with the cotangent Laplacian.

    ``E(U) = -1/2 tr(U^T L U) = 1/2 sum_{edges ij} w_ij |U_i - U_j|^2``.  The energy is
    invariant to the scale of ``V``; for a conformal bijection onto the unit
    sphere it approaches ``4 pi`` (:data:`igl_spheremap.mesh.operators.SPHERE_AREA`).
    Formula: :func:`igl_spheremap.mesh.operators.dirichlet_energy`.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int array
    U : (n, 3) float64 array
    L : (n, n) sparse matrix, optional
        Laplacian to use; default ``igl.cotmatrix(V, F)``.

    Returns
    -------
    float

    Raises
    ------
    ValueError
        ``V`` or ``U`` is not (n, 3) finite numbers with one row per vertex,
        ``F`` is not (m, 3) integer indices into them, or ``L`` is not (n, n).
    """
    V, F, U = _unitless(V, F, U)
    if L is None:
        L = igl.cotmatrix(V, F)
    elif np.shape(L) != (V.shape[0], V.shape[0]):
        raise ValueError(f"L must be ({V.shape[0]}, {V.shape[0]}), one row and column per "
                         f"vertex, got {np.shape(L)}")
    return dirichlet_energy(L, U)


def conformal_factor(V, F, U):
    """Per-vertex conformal factor ``e^{2u}`` of paper Eq. 14.

    ``e^{2u(p_i)} = sum_{T ∋ i} Area(U(T)) / sum_{T ∋ i} Area(T)``, with areas from
    ``igl.doublearea`` (flat image triangles).  The input is scaled to total
    area ``4 pi`` first, so a perfect conformal bijection has mean factor ~1
    whatever the units of ``V``.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int array
    U : (n, 3) float64 array
        The map: unit rows (within :data:`igl_spheremap.mesh.arrays.UNIT_TOL`; divide a
        sphere of radius ``R`` by ``R``).

    Returns
    -------
    e2u : (n,) float64 array
        Dimensionless; ``u = 0.5 * log(e2u)`` is the log conformal factor.

    Raises
    ------
    ValueError
        ``U`` has rows off the unit sphere, ``V`` or ``U`` is not (n, 3) finite
        numbers with one row per vertex, or ``F`` is not (m, 3) integer indices
        into them.
    """
    V, F, U = _unitless(V, F, U, unit=True)
    A = to_sphere_area(igl.doublearea(V, F) / 2.0)
    B = igl.doublearea(U, F) / 2.0
    n = V.shape[0]
    num = np.bincount(F.ravel(), weights=np.repeat(B, 3), minlength=n)
    den = np.bincount(F.ravel(), weights=np.repeat(A, 3), minlength=n)
    return num / den


def angle_distortion(V, F, U):
    """Per-corner angle distortion ``|angle_U - angle_V|`` in degrees.

    Angles come from ``igl.internal_angles`` on the input and on the flat image
    triangles (the angle-difference histograms of paper Figs. 4 and 10).

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int array
    U : (n, 3) float64 array

    Returns
    -------
    (m, 3) float64 array
        Degrees; column ``c`` is the corner at vertex ``F[:, c]``.

    Raises
    ------
    ValueError
        ``V`` or ``U`` is not (n, 3) finite numbers with one row per vertex, or
        ``F`` is not (m, 3) integer indices into them.
    """
    V, F, U = _unitless(V, F, U)
    return np.degrees(np.abs(igl.internal_angles(U, F) - igl.internal_angles(V, F)))


def area_distortion(V, F, U):
    """Per-face log area ratio of the image, both sides normalised to total area 1.

    ``log((|U(T)| / sum |U(T)|) / (|T| / sum |T|))`` with flat areas from
    ``igl.doublearea``; 0 for an equiareal map.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int array
    U : (n, 3) float64 array

    Returns
    -------
    (m,) float64 array
        Natural log, dimensionless.  ``-inf`` for a collapsed image face.

    Raises
    ------
    ValueError
        ``V`` or ``U`` is not (n, 3) finite numbers with one row per vertex, or
        ``F`` is not (m, 3) integer indices into them.
    """
    V, F, U = _unitless(V, F, U)
    A = igl.doublearea(V, F)
    B = igl.doublearea(U, F)
    with np.errstate(divide="ignore"):
        return np.log(B / B.sum()) - np.log(A / A.sum())


def image_centroid(V, F, U):
    """Area-weighted centroid of the map: ``sum_i A_i U_i / sum_i A_i``.

    ``A_i`` are the barycentric vertex areas of the *input* surface, so this is
    the discrete ``∫_M F dM / |M|`` that Möbius normalization drives to zero.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int array
    U : (n, 3) float64 array
        The map: unit rows (within :data:`igl_spheremap.mesh.arrays.UNIT_TOL`; divide a
        sphere of radius ``R`` by ``R``).

    Returns
    -------
    (3,) float64 array

    Raises
    ------
    ValueError
        ``U`` has rows off the unit sphere, ``V`` or ``U`` is not (n, 3) finite
        numbers with one row per vertex, or ``F`` is not (m, 3) integer indices
        into them.
    """
    V, F, U = _unitless(V, F, U, unit=True)
    w = vertex_areas(V, F)
    return (w @ U) / w.sum()

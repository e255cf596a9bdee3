"""Inter-surface maps through the sphere: correspondence and data transfer between two surfaces."""

import time
from dataclasses import dataclass

import numpy as np

from ..conformal_map import spherical_conformal_map
from ..options import map_options
from ..sphere.locate import locate_on_sphere
from ..sphere.transfer import barycentric_matrix
from .landmarks import landmark_map

#: A conformal map of the sphere is defined up to the 6-parameter Möbius group;
#: three landmark pairs fix it.
MIN_LANDMARKS = 3


@dataclass
class SurfaceMapResult:
    """Outcome of :func:`surface_map`: where each vertex of surface 1 lies on surface 2.

    Attributes
    ----------
    face : (n1,) int64 array
        Face of surface 2 (a row of ``map2.F``) whose spherical image contains the
        image of each vertex of surface 1.
    bary : (n1, 3) float64 array
        Barycentric coordinates in that face (non-negative, rows summing to 1).
    P : scipy.sparse.csr_matrix, shape (n1, n2)
        Interpolation matrix: ``P @ X2`` carries per-vertex data of surface 2 to
        surface 1 (non-negative, rows summing to 1, at most 3 entries per row).
    map1 : SphericalMapResult
        The landmark-matched map of surface 1 (:func:`igl_spheremap.landmark_map`).
    map2 : SphericalMapResult
        The conformal map of surface 2 (:func:`igl_spheremap.spherical_conformal_map`).
    P_reverse : scipy.sparse.csr_matrix, shape (n2, n1), or None
        The other direction (surface 1's data onto surface 2), with ``reverse=True``.
    seconds : float
        Wall time.
    timings : dict of str -> float
        Seconds of ``map2``, ``map1``, ``locate`` and ``reverse``.
    """

    face: np.ndarray
    bary: np.ndarray
    P: object
    map1: object
    map2: object
    P_reverse: object = None
    seconds: float = 0.0
    timings: dict = None

    @property
    def success(self):
        """Both maps fold-free and converged, and the landmarks reached."""
        return bool(self.map1.success and self.map2.success)

    @property
    def message(self):
        return f"surface 1: {self.map1.message}; surface 2: {self.map2.message}"

    @property
    def landmark_errors(self):
        """Angle between each landmark of surface 1 and its partner on surface 2's map, degrees."""
        return self.map1.landmark_errors

    def transfer(self, X2):
        """Per-vertex data of surface 2 carried to surface 1: ``P @ X2``.

        Parameters
        ----------
        X2 : (n2,) or (n2, d) array_like of float

        Returns
        -------
        (n1,) or (n1, d) float64 array

        Raises
        ------
        ValueError
            If ``X2`` does not have one row per vertex of surface 2.
        """
        return _apply(self.P, X2, "surface 2")

    def transfer_back(self, X1):
        """Per-vertex data of surface 1 carried to surface 2 (needs ``reverse=True``).

        Raises
        ------
        ValueError
            If the reverse direction was not computed, or ``X1`` has the wrong length.
        """
        if self.P_reverse is None:
            raise ValueError("the reverse direction was not computed: call surface_map(..., "
                             "reverse=True)")
        return _apply(self.P_reverse, X1, "surface 1")


def _apply(P, X, which):
    X = np.asarray(X, dtype=np.float64)
    if X.ndim not in (1, 2) or X.shape[0] != P.shape[1]:
        raise ValueError(f"data has shape {X.shape}; expected ({P.shape[1]},) or "
                         f"({P.shape[1]}, d), one row per vertex of {which}")
    return P @ X


def surface_map(V1, F1, V2, F2, landmarks1, landmarks2, *, mode="hard", weight=None,
                reverse=False, options=None, on_stage=None, **option_values):
    """Correspondence between two genus-0 surfaces through their spherical maps.

    Surface 2 is mapped conformally (:func:`igl_spheremap.spherical_conformal_map`);
    surface 1 by :func:`igl_spheremap.landmark_map` so that its landmarks land on
    the images of surface 2's landmarks; then each vertex of surface 1 is
    located on surface 2's spherical mesh (:func:`igl_spheremap.locate_on_sphere`,
    exact cone tests, so the gap between chordal triangles and the sphere never
    puts a point in the wrong face), which gives the barycentric interpolation
    matrix ``P`` (:func:`igl_spheremap.barycentric_matrix`).

    Parameters
    ----------
    V1, F1, V2, F2 : arrays
        The two closed genus-0 triangle meshes ((n1, 3), (m1, 3), (n2, 3), (m2, 3)).
    landmarks1, landmarks2 : (k,) array_like of int
        Corresponding vertex indices, ``k >= 3``.
    mode, weight
        As in :func:`igl_spheremap.landmark_map`.
    reverse : bool
        Also locate surface 2's vertices on surface 1's map (``P_reverse``).
    options : MapOptions or dict, optional
        Options of both maps.
    on_stage : callable, optional
        ``on_stage(text)`` before each stage (what it does), e.g. to print progress.
    **option_values
        Fields of :class:`igl_spheremap.MapOptions`.

    Returns
    -------
    SurfaceMapResult

    Raises
    ------
    ValueError
        Fewer than 3 landmark pairs (a conformal map is only defined up to a
        6-parameter Möbius group), lists of different lengths, bad indices, or
        the errors of :func:`igl_spheremap.landmark_map`.
    MeshError
        If a mesh is invalid.
    """
    t0 = time.perf_counter()
    opts = map_options(options, **option_values)
    l1, l2 = _landmark_pairs(landmarks1, landmarks2)
    timings = {}
    say = on_stage or (lambda text: None)
    t = time.perf_counter()
    say(f"mapping surface 2 ({len(V2):,} vertices) onto the sphere")
    map2 = spherical_conformal_map(V2, F2, opts)
    if l2.max() >= map2.U.shape[0] or l2.min() < 0:
        raise ValueError(f"{int(((l2 < 0) | (l2 >= map2.U.shape[0])).sum())} indices of "
                         f"landmarks2 outside 0..{map2.U.shape[0] - 1}")
    timings["map2"] = time.perf_counter() - t
    t = time.perf_counter()
    say(f"mapping surface 1 ({len(V1):,} vertices) with its {len(l1)} landmarks on surface 2's")
    map1 = landmark_map(V1, F1, l1, map2.U[l2], mode=mode, weight=weight, options=opts)
    timings["map1"] = time.perf_counter() - t
    t = time.perf_counter()
    say("locating surface 1's vertices on surface 2")
    face, bary = locate_on_sphere(map2.U, map2.F, map1.U)
    P = barycentric_matrix(face, bary, map2.F, map2.U.shape[0])
    timings["locate"] = time.perf_counter() - t
    P_reverse = None
    if reverse:
        t = time.perf_counter()
        face21, bary21 = locate_on_sphere(map1.U, map1.F, map2.U)
        P_reverse = barycentric_matrix(face21, bary21, map1.F, map1.U.shape[0])
        timings["reverse"] = time.perf_counter() - t
    return SurfaceMapResult(face=face, bary=bary, P=P, map1=map1, map2=map2,
                            P_reverse=P_reverse, seconds=time.perf_counter() - t0,
                            timings=timings)


def _landmark_pairs(landmarks1, landmarks2):
    l1, l2 = np.asarray(landmarks1), np.asarray(landmarks2)
    if l1.ndim != 1 or l2.ndim != 1:
        raise ValueError("landmarks1 and landmarks2 must be 1-D arrays of vertex indices")
    if l1.size != l2.size:
        raise ValueError(f"{l1.size} landmarks on surface 1 but {l2.size} on surface 2: they "
                         "are pairs")
    if l1.size < MIN_LANDMARKS:
        raise ValueError(f"{l1.size} landmark pairs; at least {MIN_LANDMARKS} are needed: a "
                         "conformal map of the sphere is only defined up to the 6-parameter "
                         "Möbius group, which 3 pairs fix")
    for name, lm in (("landmarks1", l1), ("landmarks2", l2)):
        if lm.dtype == bool or not np.issubdtype(lm.dtype, np.integer):
            raise ValueError(f"{name} must be integer vertex indices, got dtype {lm.dtype}")
    return l1.astype(np.int64), l2.astype(np.int64)

"""Coarse levels of the distortion stage: moves larger than a few triangles of surface 1.

The distortion stage (:mod:`igl_spheremap.uses.surface_arap`) moves each vertex
of surface 1's spherical map by local/global steps and stops in the first local
minimum near the landmark bend's map; on the real benchmark pairs the true
correspondence lies in a basin of lower energy.  Before the full stage, the same
stage runs on a few coarse versions of surface 1, coarsest first, against the
full surface 2; the fine map follows each coarse one.

A coarse level (:func:`coarse_level`) has ``count`` vertices of surface 1: the
landmarks first, then farthest-point samples in space, without points closer
than :data:`SEPARATION` on the sphere (the conformal map crowds limbs into
regions of the sphere of 1e-8 and less, where the convex hull cannot tell points
apart).  Its faces are the convex hull of their places on the sphere, oriented
outward: a fold-free spherical triangulation (the spherical Delaunay one), so no
decimation of surface 1 is needed and every coarse map starts fold-free.  The
coarse surface is those vertices of surface 1 with these faces.

The fine map follows the coarse map step by step (:func:`follow`): every
accepted step of the coarse stage moves each fine vertex with the coarse face
that contains it on the sphere (same barycentric coordinates in the moved
face), then :func:`igl_spheremap.sphere.folds.fold_free_blend` keeps it
fold-free; small steps fold few faces, so little is pulled back (on cat
reference -> cat 07, one jump from the first coarse map to the last left the
fine stage a start of ARAP energy 8.2, step by step 5.4; docs/decisions.md).
"""

from functools import partial

import numpy as np
from scipy.spatial import ConvexHull, cKDTree

from ..errors import plural
from ..mesh.arrays import cross_rows, moved_unit_rows
from ..sphere.folds import count_folds, fold_free_blend, map_degree
from ..sphere.locate import COVER_TOL, locate_on_sphere
from .landmark_bend import farthest_points
from .side_by_side import Chain
from .surface_arap import refine

#: Vertex counts of the coarse levels, coarsest first, that lowered the error of the real
#: benchmark pairs (docs/decisions.md); as the default, levels with more than half of
#: surface 1's vertices are skipped (given levels there are refused: :func:`checked_levels`).
LEVELS = (300, 1000)

#: Fewest vertices of a coarse level: its faces are the convex hull of their places on the
#: sphere, which needs 4 points.
MIN_LEVEL = 4

#: Smallest distance on the unit sphere between two vertices of a coarse level (landmarks
#: excepted): below, the convex hull of the points loses some of them to rounding.
SEPARATION = 1e-5


def checked_levels(levels, n):
    """The coarse levels of a surface of ``n`` vertices, given levels checked.

    A level above half of the surface's vertices is skipped by the distortion stage
    (:meth:`igl_spheremap.uses.correspondence.Correspondence.coarse_levels_run`): the
    default's are skipped quietly on small surfaces, a given one is refused.

    Parameters
    ----------
    levels : sequence of int or None
        Vertex counts, coarsest first; None: :data:`LEVELS`.
    n : int
        Number of vertices of the surface.

    Returns
    -------
    tuple of int

    Raises
    ------
    ValueError
        If a given level is not an integer, has fewer than :data:`MIN_LEVEL` vertices or
        more than half of ``n`` (the message gives the count of such levels and the first
        five of them).
    """
    if levels is None:
        return LEVELS
    levels = tuple(levels)
    whole = [isinstance(c, (int, np.integer)) and not isinstance(c, bool) for c in levels]
    _refuse([c for c, w in zip(levels, whole) if not w], "not whole numbers of vertices")
    _refuse([c for c in levels if c < MIN_LEVEL],
            f"below {MIN_LEVEL} vertices (a level's faces are the convex hull of its points)")
    _refuse([c for c in levels if 2 * c > n], f"above half of surface 1's {n:,} vertices "
                                              f"(such a level is skipped; at most {n // 2:,})")
    return tuple(int(c) for c in levels)


def _refuse(bad, problem):
    """ValueError naming the count of the coarse levels ``bad`` and the first five, if any."""
    if bad:
        shown = ", ".join(str(int(c)) if isinstance(c, (int, np.integer)) and not
                          isinstance(c, bool) else repr(c) for c in bad[:5])
        raise ValueError(f"{plural(len(bad), 'coarse level')} {problem}: {shown}"
                         + (", ..." if len(bad) > 5 else ""))


def coarse_level(V, U, first, count):
    """A coarse version of a surface: vertices and their spherical triangulation (module doc).

    Parameters
    ----------
    V : (n, 3) float64 array
        The surface's vertices.
    U : (n, 3) float64 array
        Its fold-free spherical map (unit rows).
    first : (k,) int64 array
        Vertices that must be coarse vertices (landmarks).
    count : int
        Number of coarse vertices asked for (fewer come back when points are dropped).

    Returns
    -------
    S : (c,) int64 array or None
        The coarse vertices, ``first`` in its order first; None when the convex hull lost
        one of ``first`` or its faces fold on the sphere.
    Fc : (mc, 3) int64 array or None
        Faces on ``S``'s numbering, oriented outward.
    """
    S = farthest_points(V, first, count)
    drop = np.zeros(S.size, dtype=bool)
    pairs = np.sort(cKDTree(U[S]).query_pairs(SEPARATION, output_type="ndarray"), axis=1)
    for a, b in pairs[np.lexsort(pairs.T[::-1])]:  # the later sample of each close pair goes
        if not drop[a] and b >= len(first):
            drop[b] = True
    S = S[~drop]
    P = U[S]
    Fc = ConvexHull(P).simplices.astype(np.int64)
    normal = cross_rows(P[Fc[:, 1]] - P[Fc[:, 0]], P[Fc[:, 2]] - P[Fc[:, 0]])
    inward = np.einsum("ij,ij->i", normal, P[Fc].sum(axis=1)) < 0
    Fc[inward] = Fc[inward][:, ::-1]
    used = np.unique(Fc)
    if used.size < len(first) or np.any(used[:len(first)] != np.arange(len(first))):
        return None, None
    renumber = np.full(S.size, -1, dtype=np.int64)
    renumber[used] = np.arange(used.size)
    S, Fc = S[used], renumber[Fc]
    if count_folds(Fc, U[S]) > 0:
        return None, None
    return S, Fc


def follow(F, U, S, Fc, Uc_old, Uc_new):
    """The fine map ``U`` moved with the coarse map ``Uc_old -> Uc_new`` ((n, 3) float64).

    Each fine vertex moves by the displacement of the point with its barycentric
    coordinates in the coarse face that contains it on the sphere (the displacement, not
    the new point: where the conformal map crowds a region below the rounding of those
    coordinates, the interpolated point is not the vertex itself, and a coarse step of
    zero would move it); the coarse vertices ``S`` take their new places;
    then :func:`igl_spheremap.sphere.folds.fold_free_blend` pulls vertices back
    toward ``U`` until no face of ``F`` folds.

    Parameters
    ----------
    F : (m, 3) int64 array
        Fine faces.
    U : (n, 3) float64 array
        Fold-free fine map.
    S : (c,) int64 array
        Coarse vertices (fine indices), ``Uc_old == U[S]``.
    Fc : (mc, 3) int64 array
        Coarse faces.
    Uc_old, Uc_new : (c, 3) float64 arrays
        Fold-free coarse maps (unit rows).
    """
    face, bary = locate_on_sphere(Uc_old, Fc, U)
    moved = moved_unit_rows(U, U + np.einsum("ij,ijk->ik", bary, (Uc_new - Uc_old)[Fc[face]]))
    moved[S] = Uc_new
    return fold_free_blend(F, U, moved)[0]


class _Uncovered(Exception):
    """A coarse step whose faces do not cover the sphere once (:func:`coarse_stage`)."""


def coarse_stage(problem, F, U, S, Fc, iterations, workers=1):
    """The distortion stage on one coarse level, the fine map following it step by step.

    The stage ends early, at the last coarse map the fine map could follow, when a step
    leaves the coarse faces fold-free but no longer covering the sphere once (a coarse
    face whose edge spans nearly half a great circle: its arcs no longer match its
    neighbours'); the fine map cannot be located in such faces.

    The fine map's steps (:func:`follow`) depend on the coarse maps, not the other way:
    with ``workers > 1`` they run in a worker process beside the coarse stage
    (:class:`igl_spheremap.uses.side_by_side.Chain`), with the same result.

    Parameters
    ----------
    problem : igl_spheremap.uses.surface_arap.SurfaceARAP
        The coarse surface's problem (vertices ``S`` of surface 1, faces ``Fc``).
    F : (m, 3) int64 array
        Surface 1's faces.
    U : (n, 3) float64 array
        Surface 1's fold-free map.
    S, Fc : arrays
        The level (:func:`coarse_level`).
    iterations : int
        Largest number of iterations of the coarse stage.
    workers : int
        Processes working at once (1: the fine map follows in this process).

    Returns
    -------
    U : (n, 3) float64 array
        The fine map after the coarse stage, fold-free.
    history : list of float
        The energies of the coarse maps the fine map followed.
    """
    followed, history = U[S], []
    chain = Chain(partial(_followed, F, S, Fc), (U, followed), workers)

    def step(Uc, value):  # at every accepted coarse map, the start first
        nonlocal followed
        if history and Uc is followed:
            return
        if history:
            if abs(map_degree(Fc, Uc) - 1.0) > COVER_TOL:
                raise _Uncovered
            chain.send(Uc)
            followed = Uc
        history.append(value)

    try:
        Uc, _, hist = refine(problem, followed, problem.phi.start(followed), iters=iterations,
                             callback=lambda it, Uc, value: step(Uc, value))
        step(Uc, hist[-1])
    except _Uncovered:
        pass
    except BaseException:
        chain.close()
        raise
    return chain.result()[0], history


def _followed(F, S, Fc, state, Uc_new):
    """``(U, Uc)`` -> the fine map after :func:`follow` to ``Uc_new``, and ``Uc_new``
    (:func:`coarse_stage`'s chain step)."""
    U, Uc_old = state
    return follow(F, U, S, Fc, Uc_old, Uc_new), Uc_new

"""Maps between two genus-0 surfaces through their spherical maps: correspondence and data transfer.

:func:`surface_map` puts surface 1 in correspondence with surface 2 through the
sphere and keeps the correspondence bijective:

1. both surfaces are mapped conformally (:func:`igl_spheremap.spherical_conformal_map`);
2. surface 1's map is aligned to surface 2's (:mod:`igl_spheremap.uses.alignment`):
   the Möbius fit of the landmarks, or without enough landmarks rotations found by
   spherical-harmonic correlation of functions built from each surface's
   extremities; and in either case the Möbius fit to the given pairs with pairs of a
   functional map (:mod:`igl_spheremap.uses.functional_map`), which then serve as
   landmarks too;
3. with landmarks, surface 1's map is bent until they sit on surface 2's landmark
   images (:func:`igl_spheremap.uses.landmark_bend.place`), keeping what it reached
   when not every landmark can be placed without folds; then onto the functional map's
   pairs at fine tips the conformal maps crowd, such as fingertips
   (:mod:`igl_spheremap.uses.fine_tips`);
4. the distortion of the map between the surfaces is lowered under a fold-free
   constraint on the sphere (:mod:`igl_spheremap.uses.surface_arap`): surface 2's
   map stays fixed, surface 1's vertices slide over surface 2;
5. where the bend leaves landmarks unplaced (``mode="hard"``), stages 2–4 run once more
   on both maps relaxed toward area balance; the run on the conformal maps is finished
   only if that one leaves landmarks unplaced too, and the run placing more is kept;
6. each vertex of either surface is located on the other's spherical map
   (:func:`igl_spheremap.locate_on_sphere`): ``P`` and ``P_reverse``, the barycentric
   forms of the bijection and of its inverse.

Each of these starts is refined a little and the one with the least distortion both
ways (the map and its inverse) is refined to the end.
"""

import time
import warnings
from dataclasses import dataclass, field

import numpy as np

from ..conformal_map import area_balanced_result, map_validated
from ..errors import SphericalMapWarning, plural
from ..mesh.validate import validate_mesh
from ..options import map_options
from ..sphere.folds import count_folds
from ..sphere.geodesics import angles
from ..sphere.locate import locate_on_sphere
from ..sphere.transfer import barycentric_matrix
from . import correspondence as corr
from .alignment import spectral_pairs
from .coarse_to_fine import checked_levels
from .landmarks import landmark_vertices
from .side_by_side import DEFAULT_WORKERS, Background, checked_workers, side_by_side
from .surface_arap import checked_robust_scale, to_sphere_scale
from .surface_distortion import face_distortion

MODES = ("hard", "soft")


@dataclass
class SurfaceMapResult:
    """Outcome of :func:`surface_map`: where each vertex of surface 1 lies on surface 2, and back.

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
        Surface 1's final spherical map (``map1.U``, ``map1.F``; its ``rounds`` are
        those of its conformal map, plus an ``"area_balanced"`` round when the relaxed
        maps were the common domain; ``folds`` and ``message`` the final map's).
    map2 : SphericalMapResult
        Surface 2's map (fixed throughout): its conformal map, or that map relaxed toward
        area balance (its last round ``"area_balanced"``) when unplaced landmarks sent the
        correspondence to the relaxed maps (see :func:`surface_map`).
    P_reverse : scipy.sparse.csr_matrix, shape (n2, n1), or None
        The other direction: surface 1's data onto surface 2 (``reverse=True``).
    success : bool
        Both maps fold-free and the landmarks met: on their partners to rounding
        (``mode="hard"``), or within ``landmark_tol`` (``mode="soft"``).
    message : str
        What each stage did and, when ``success`` is False, how far it got.
    landmark_errors : (k,) float64 array
        Angle between each landmark's image and its partner's on surface 2's map, degrees.
    landmark_distances : (k,) float64 array
        Distance on surface 2 between where the map puts each landmark of
        surface 1 and its partner, divided by ``sqrt(area of surface 2)``.
    distortion : (m1,) float64 array
        Per face of surface 1 (rows of ``map1.F``), the symmetric Dirichlet
        distortion ``(s1^2 + s2^2 + s1^-2 + s2^-2) / 4`` of the map onto surface 2
        (singular values ``s`` of its Jacobian, surfaces scaled to equal area; 1: isometric).
    stages : list of dict
        Surface 1's map after each stage: ``name``, ``U`` (n1, 3; input order), ``note``.
    seconds : float
        Wall time.
    timings : dict of str -> float
        Seconds per stage: ``maps`` (the two conformal maps and the functional map's
        pairs, side by side), ``map2`` and ``map1`` (each conformal map's own), ``align``,
        ``landmarks``, ``coarse``, ``refine`` (the screened starts' seconds summed over the
        processes that ran them), ``balanced`` (the relaxed maps, when a second
        run was needed), ``locate``, ``reverse``.
    """

    face: np.ndarray = field(repr=False)
    bary: np.ndarray = field(repr=False)
    P: object = field(repr=False)
    map1: object = field(repr=False)
    map2: object = field(repr=False)
    P_reverse: object = field(default=None, repr=False)
    success: bool = False
    message: str = ""
    landmark_errors: np.ndarray = field(default=None, repr=False)
    landmark_distances: np.ndarray = field(default=None, repr=False)
    distortion: np.ndarray = field(default=None, repr=False)
    stages: list = field(default_factory=list, repr=False)
    seconds: float = 0.0
    timings: dict = field(default_factory=dict)

    @property
    def folds(self):
        """Folded faces of both spherical maps (0 for a bijection)."""
        return int(self.map1.folds + self.map2.folds)

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
        """Per-vertex data of surface 1 carried to surface 2: ``P_reverse @ X1``.

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


def surface_map(V1, F1, V2, F2, landmarks1=None, landmarks2=None, *, mode="hard", weight=None,
                landmark_tol=None, iterations=corr.ITERATIONS, descriptor_weight=None,
                coarse_levels=None, robust_scale="auto", reverse=True, workers=DEFAULT_WORKERS,
                options=None, on_stage=None, **option_values):
    """Bijective correspondence between two closed genus-0 surfaces through their spherical maps.

    See the module documentation for the stages.  Surface 2's map is its
    conformal map; surface 1's map is aligned to it, bent to the landmarks and
    then moved so that the map between the two surfaces is as rigid as possible
    (Sorkine, Alexa 2007) while surface 1's map stays fold-free, so that the
    correspondence stays a bijection (Schmidt, Born, Campen, Kobbelt, TOG 2019).
    In ``mode="hard"``, when landmarks stay unplaced, everything after the conformal
    maps is run once more on both maps relaxed toward area balance
    (:data:`BALANCED_ITERATIONS` iterations of the symmetric Dirichlet energy;
    :func:`igl_spheremap.conformal_map.area_balanced_result`), whose crowding is far
    less, and the run that placed more landmarks is returned.

    Parameters
    ----------
    V1, F1, V2, F2 : arrays
        The two closed, connected, genus-0 triangle meshes ((n1, 3), (m1, 3),
        (n2, 3), (m2, 3)); any units.
    landmarks1, landmarks2 : (k,) array_like of int, optional
        Corresponding vertex indices (pairs in the same order), ``k >= 0``.  With
        ``k >= 3`` their Möbius fit is one alignment, with fewer a rotation search
        offers several; a functional map offers one more in either case, and the
        least distorted is kept (:mod:`igl_spheremap.uses.alignment`).
    mode : {"hard", "soft"}
        ``"hard"``: each landmark ends exactly on its partner, where that is
        possible without folds (the others are pulled toward it by a spring);
        ``"soft"``: every landmark is pulled toward its partner by a spring of
        stiffness ``weight``.
    weight : float, optional
        ``mode="soft"`` only: the springs' stiffness (default
        :data:`igl_spheremap.uses.correspondence.SPRING`; surfaces scaled to area ``4 pi``).
    landmark_tol : float, optional
        ``mode="soft"`` only: the largest landmark distance (on surface 2, over
        ``sqrt(area of surface 2)``) that counts as met (default
        :data:`igl_spheremap.uses.correspondence.SOFT_TOL`).
    iterations : int
        Largest number of iterations of the distortion stage (0: none).
    descriptor_weight : float, optional
        Weight ``w`` of a descriptor term added to the distortion stage,
        ``w sum_i A_i |d1(i) - d2(X_i)|^2 / k`` over surface 1's vertices ``i`` (areas
        ``A_i``, surfaces scaled to area ``4 pi``), ``d`` the harmonic landmark
        coordinates of each surface (:mod:`igl_spheremap.uses.descriptors`); 0 turns it
        off.  It needs given landmarks placed on their targets (the pairs the alignment
        finds are not used), so a weight above 0 without landmarks is refused.  The term
        chooses the basin; the stage then runs again, without it where the map is
        near-isometric (:func:`~igl_spheremap.uses.surface_arap.auto_robust_scale`'s test), so
        that the map returned minimizes the distortion alone (the descriptors of two
        triangulations of one surface differ, and would hold the map off the exact one), and
        elsewhere with :data:`~igl_spheremap.uses.correspondence.LAST_STAGE_DESCRIPTORS` (a
        tenth) of its weight, which keeps the landmarks' say between two shapes that stretch
        (docs/decisions.md).  Default:
        :data:`igl_spheremap.uses.correspondence.DESCRIPTOR_WEIGHT` (300) with at least
        :data:`~igl_spheremap.uses.correspondence.DESCRIPTOR_MIN_LANDMARKS` (8) landmark
        pairs, else 0 (README, "Maps between surfaces").
    coarse_levels : sequence of int, optional
        Vertex counts of coarse versions of surface 1 on which the distortion stage
        runs first, coarsest first, the map following (:mod:`igl_spheremap.uses.coarse_to_fine`),
        each from 4 to half of surface 1's vertices; empty: none.  Default (None):
        :data:`igl_spheremap.uses.coarse_to_fine.LEVELS`, which lowered the mean error of
        the real benchmark pairs (README, "Maps between surfaces"), those above half of
        surface 1's vertices skipped.
    robust_scale : float, "auto" or None
        For articulated surfaces (poses of one body): the last distortion stage charges
        each triangle's distortion ``|J - R|`` (a stretch, dimensionless) quadratically up
        to this scale and linearly beyond, the pseudo-Huber penalty of
        :func:`igl_spheremap.uses.surface_arap.robust_penalty`, so that the limbs stay
        rigid and the bent joints take the distortion instead of the parts around them.
        Not for smooth deformations or different species, where nothing is rigid.
        ``"auto"`` (default): the scale
        :data:`~igl_spheremap.uses.surface_arap.AUTO_ROBUST_SCALE` (0.01) where the map
        before the last stage is near-isometric (area-weighted median ``|J - R|`` below
        :data:`~igl_spheremap.uses.surface_arap.NEAR_ISOMETRIC`,
        :func:`~igl_spheremap.uses.surface_arap.auto_robust_scale`) and the penalty's map comes
        out piecewise rigid (:func:`~igl_spheremap.uses.surface_arap.piecewise_rigid`: not so on
        a body of another shape), else plain; None: plain as-rigid-as-possible (README, "Maps
        between surfaces").
    reverse : bool
        Also compute ``P_reverse``.
    workers : int
        Processes working at once on the stages that do not depend on each other
        (:func:`igl_spheremap.uses.side_by_side.side_by_side`): the two conformal maps
        and the functional map's pairs (which go on beside the screening of the starts that
        do not need them), the screening of the aligned starts, the two starts finished
        where the screening's scores disagree, the two relaxed maps, and on each coarse level
        the fine map following the coarse steps.  Default 3; ``1``
        runs everything in this process (as it does inside a Dask or ``multiprocessing``
        worker, which may not start processes).  The result does not depend on it.
    options : MapOptions or dict, optional
        Options of the conformal maps and of the landmark relaxation.
    on_stage : callable, optional
        ``on_stage(text)`` before each stage (what it does), e.g. to print progress.
    **option_values
        Fields of :class:`igl_spheremap.MapOptions`.

    Returns
    -------
    SurfaceMapResult
        ``success`` is False when landmarks could not be met or a map has folds;
        the map returned is then the best fold-free one reached and ``message``
        says how far it got.

    Raises
    ------
    ValueError
        Landmark lists of different lengths, bad indices or duplicates, an
        unknown ``mode``, ``weight`` or ``landmark_tol`` with ``mode="hard"``, or
        a non-positive one; a negative or non-finite ``descriptor_weight``, or one above 0
        without landmarks; a
        ``robust_scale`` other than ``"auto"``, None or a finite positive number; ``workers``
        not an integer >= 1; given ``coarse_levels`` with levels that are not integers, below
        4 vertices or above half of surface 1's vertices (a level there would be skipped; the
        message counts them: :func:`igl_spheremap.uses.coarse_to_fine.checked_levels`).
    MeshError
        If a mesh is invalid.

    Warns
    -----
    SphericalMapWarning
        If the result is not a success (its message).
    """
    t0 = time.perf_counter()
    opts = map_options(options, **option_values)
    weight, tol = _mode_values(mode, weight, landmark_tol)
    if descriptor_weight is not None and not (np.isfinite(descriptor_weight)
                                              and descriptor_weight >= 0):
        raise ValueError(f"descriptor_weight must be finite and >= 0, got {descriptor_weight!r}")
    robust_scale = checked_robust_scale(robust_scale)
    workers = checked_workers(workers)
    say = on_stage or (lambda text: None)
    timings = {}
    with opts.blas_limit():
        mesh1, mesh2 = validate_mesh(V1, F1), validate_mesh(V2, F2)
        coarse_levels = checked_levels(coarse_levels, mesh1.V.shape[0])
        l1, l2 = _landmark_pairs(mesh1, mesh2, landmarks1, landmarks2)
        if descriptor_weight is None:
            descriptor_weight = corr.default_descriptor_weight(l1.size)
        elif descriptor_weight > 0 and l1.size == 0:
            raise ValueError("descriptor_weight weighs descriptors built from the given landmark "
                             "pairs; without landmarks there are none and it would have no "
                             "effect: pass landmarks1 and landmarks2 or leave it out")
        t = time.perf_counter()
        say(f"mapping surface 1 ({mesh1.V.shape[0]:,} vertices) and surface 2 "
            f"({mesh2.V.shape[0]:,} vertices) onto the sphere and finding a functional map's "
            f"pairs" + (f", up to {min(workers, 3)} processes side by side" if workers > 1 else ""))
        pairs = Background((_pairs_job, mesh1, mesh2, l1, l2, opts), workers)
        try:
            (map2, problem2, timings["map2"]), (map1, problem1, timings["map1"]) = side_by_side(
                [(_map_job, mesh2, opts), (_map_job, mesh1, opts)], max(1, workers - 1))
            timings["maps"] = time.perf_counter() - t
            job = corr.Correspondence(problem1, map1, problem2, map2, l1, l2, mode, weight, say,
                                      float(descriptor_weight), coarse_levels, workers,
                                      robust_scale)
            relax = mode == "hard" and l1.size > 0 and not (map1.folds or map2.folds)
            outcome = job.run(iterations, timings, defer=relax, pairs=pairs)
        finally:
            pairs.close()
        if relax and not job.placed.all():
            job, U1, stages, notes = _balanced_domain(job, outcome, iterations, timings, workers)
        else:
            U1, stages, notes = outcome
        t = time.perf_counter()
        say("locating each surface's vertices on the other's spherical map")
        out = _outcome(job, U1, reverse, tol, notes, timings)
    out.stages = [dict(s, U=mesh1.to_input(s["U"])) for s in stages]
    out.seconds = time.perf_counter() - t0
    if not out.success:
        warnings.warn(f"surface_map: {out.message}", SphericalMapWarning, stacklevel=2)
    return out


def _map_job(mesh, opts):
    """``(result, problem, seconds)`` of one surface's conformal map (a :func:`side_by_side` job)."""
    t = time.perf_counter()
    with opts.blas_limit():
        result, problem = map_validated(mesh, opts)
    return result, problem, time.perf_counter() - t


def _pairs_job(mesh1, mesh2, l1, l2, opts):
    """The functional map's pairs of the two surfaces (a :func:`side_by_side` job)."""
    with opts.blas_limit():
        return spectral_pairs(to_sphere_scale(mesh1.V, mesh1.F), mesh1.F,
                              to_sphere_scale(mesh2.V, mesh2.F), mesh2.F, l1, l2)


def _relax_job(result, problem):
    """A conformal map relaxed part way toward area balance (a :func:`side_by_side` job)."""
    with problem.options.blas_limit():
        return area_balanced_result(result, problem, max_iter=BALANCED_ITERATIONS)


#: Iterations of the relaxation toward the area-balanced sphere
#: (:func:`igl_spheremap.conformal_map.area_balanced_result`) that makes the common domain of
#: a second run when the conformal maps leave landmarks unplaced (``docs/decisions.md``).
BALANCED_ITERATIONS = 300


def _balanced_domain(job, outcome, iterations, timings, workers):
    """``(job, U1, stages, notes)``: the run of ``job`` on the conformal maps, or the run again
    with both maps relaxed toward area balance if that places more of the given landmarks.

    Where a conformal map crowds a limb, landmarks far apart on the surface land
    micro-radians apart on the sphere, and no fold-free bend of the other map squeezes
    its triangles in between them: landmark placement fails on the domain, not on the
    correspondence.  Relaxing both maps toward area balance (the symmetric Dirichlet
    energy, fold-free) spreads those regions out.  It is not the first domain because
    where every landmark is placed the conformal maps' alignment was as good or better.

    ``outcome`` is what ``job.run`` returned: None when it stopped after the bend that
    left given landmarks unplaced (``defer``).  That run is finished (``job.resume``) only
    if the relaxed maps' run does not place every landmark either: finishing it first, only
    to discard it, took half the time of the pairs that need the relaxed maps
    (docs/decisions.md).
    """
    t = time.perf_counter()
    missed = int((~job.placed).sum())
    job.say(f"{plural(missed, 'landmark')} could not be placed on the conformal maps: relaxing "
            "both maps toward area balance")
    maps = side_by_side([(_relax_job, job.map1, job.problem1),
                         (_relax_job, job.map2, job.problem2)], workers)
    timings["balanced"] = time.perf_counter() - t
    other = None
    if not (maps[0].folds or maps[1].folds):
        other, more = job.in_domain(*maps), {}
        U1, stages, notes = other.run(iterations, more)
        corr.add_timings(timings, more)
    k, b = job.placed.size, -1 if other is None else int(other.placed.sum())
    if outcome is None and b < k:
        job.say("finishing the run on the conformal maps")
        outcome = job.resume(iterations, timings)
    if other is None:
        return (job, *outcome)
    a = int(job.placed.sum())
    head = (f"{a} of {k} landmarks placed on the conformal maps, {b} on both maps relaxed "
            f"toward area balance ({BALANCED_ITERATIONS} iterations of the symmetric "
            "Dirichlet energy)")
    if b > a:
        return other, U1, stages, [head + ": the correspondence on the relaxed maps"] + notes
    return job, outcome[0], outcome[1], outcome[2] + [head + ": the run on the conformal maps "
                                                      "kept"]


def _mode_values(mode, weight, landmark_tol):
    """The springs' stiffness and the landmark tolerance of ``mode``; ValueErrors otherwise."""
    if mode not in MODES:
        raise ValueError(f"unknown mode {mode!r}; expected one of {list(MODES)}")
    if mode == "hard":
        if weight is not None or landmark_tol is not None:
            raise ValueError("weight and landmark_tol apply to mode='soft' only")
        return corr.SPRING, corr.HARD_TOL
    weight = corr.SPRING if weight is None else weight
    tol = corr.SOFT_TOL if landmark_tol is None else landmark_tol
    for name, x in (("weight", weight), ("landmark_tol", tol)):
        if not (np.isfinite(x) and x > 0):
            raise ValueError(f"{name} must be a finite number > 0, got {x}")
    return float(weight), float(tol)


def _landmark_pairs(mesh1, mesh2, landmarks1, landmarks2):
    """Landmark pairs in the validated meshes' numbering ((k,) int64 each); ValueErrors otherwise."""
    l1 = np.zeros(0, np.int64) if landmarks1 is None else np.asarray(landmarks1)
    l2 = np.zeros(0, np.int64) if landmarks2 is None else np.asarray(landmarks2)
    if l1.ndim != 1 or l2.ndim != 1:
        raise ValueError("landmarks1 and landmarks2 must be 1-D arrays of vertex indices")
    if l1.size != l2.size:
        raise ValueError(f"{plural(l1.size, 'landmark')} on surface 1 but {l2.size} on surface 2: "
                         "they are pairs")
    if l1.size == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    for name, lm in (("landmarks1", l1), ("landmarks2", l2)):
        if lm.dtype == bool or not np.issubdtype(lm.dtype, np.integer):
            raise ValueError(f"{name} must be integer vertex indices, got dtype {lm.dtype}")
    return (landmark_vertices(mesh1, l1, "surface 1 landmark"),
            landmark_vertices(mesh2, l2, "surface 2 landmark"))


def _outcome(job, U1, reverse, tol, notes, timings):
    """Point location both ways, the landmark errors, the verdict: the :class:`SurfaceMapResult`."""
    t = time.perf_counter()
    mesh1, mesh2 = job.problem1.mesh, job.problem2.mesh
    U2, F2, F1 = job.U2, job.problem2.F, job.problem1.F
    face, bary = locate_on_sphere(U2, F2, U1)
    P = barycentric_matrix(face, bary, mesh2.F_input, mesh2.n_input)
    P = P[mesh1.to_input(np.arange(U1.shape[0]))].tocsr()
    timings["locate"] = time.perf_counter() - t
    P_rev = None
    if reverse:
        t = time.perf_counter()
        f21, b21 = locate_on_sphere(U1, F1, U2)
        P_rev = barycentric_matrix(f21, b21, mesh1.F_input, mesh1.n_input)
        P_rev = P_rev[mesh2.to_input(np.arange(U2.shape[0]))].tocsr()
        timings["reverse"] = time.perf_counter() - t
    X = np.einsum("ij,ijk->ik", bary, job.V2s[F2[face]])
    dist = np.linalg.norm(X[job.l1] - job.V2s[job.l2], axis=1) / np.sqrt(4 * np.pi)
    folds1 = count_folds(F1, U1)
    met = bool(dist.size == 0 or dist.max() <= tol)
    ok = met and folds1 == 0 and job.map2.folds == 0
    if dist.size:
        notes.append(f"largest landmark distance {dist.max():.3g} sqrt(area) "
                     f"({'within' if met else 'above'} {tol:g})")
    notes += [f"surface {k}: {mesh.reorientation}, use map{k}.F" for k, mesh in
              ((1, mesh1), (2, mesh2)) if mesh.reorientation]
    message = "; ".join(notes)
    map1 = job.final_map1(U1, folds1, message)
    return SurfaceMapResult(
        face=mesh1.to_input(face), bary=mesh1.to_input(bary), P=P, map1=map1, map2=job.map2,
        P_reverse=P_rev, success=bool(ok), message=message,
        landmark_errors=np.degrees(angles(U1[job.l1], U2[job.l2])), landmark_distances=dist,
        distortion=face_distortion(job.V1s, F1, X), timings=timings)

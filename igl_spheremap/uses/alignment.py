"""Aligning surface 1's conformal spherical map to surface 2's before they are put in correspondence.

* With three or more landmark pairs: the Möbius transformation that best fits
  surface 1's landmark images to surface 2's
  (:func:`igl_spheremap.sphere.mobius.mobius_fit`), its translation halved while
  it folds faces (a Möbius transformation can flip large flat image triangles).
* With fewer: both maps are Möbius-centred by area
  (:func:`igl_spheremap.sphere.mobius.mobius_center`), which leaves a rotation to
  find (Baden, Crane, Kazhdan, "Möbius Registration", SGP 2018).  The intrinsic
  function correlated is built from each surface's extremities, the local
  maxima of the average geodesic distance (tips of limbs, head, tail: Lipman,
  Funkhouser, "Möbius voting for surface correspondence", TOG 2009, sample
  them the same way): a bump on the sphere at each extremity's image, weighted
  by its average geodesic distance.  The log conformal factor itself does not
  do: the limbs it characterizes are crushed into caps too small for a
  low-degree expansion, and what remains, the body, is nearly round.  The
  rotations that best correlate the two functions are found over all of SO(3)
  by spherical harmonics (:func:`igl_spheremap.sphere.harmonics.best_rotations`);
  under each, the extremities are paired (nearest images, one to one), and
  with three or more pairs the Möbius fit to them refines the alignment and
  the pairs serve as landmarks.  Several hypotheses are returned.  The best
  correlation over improper rotations (the mirror image) is reported too.
* With any number of landmarks, one more hypothesis comes from a functional map
  refined by ZoomOut (:func:`spectral_start`,
  :mod:`igl_spheremap.uses.functional_map`): pairs of its vertex map at
  farthest-point samples join the given pairs, fix a Möbius fit and serve as
  landmarks.  It is right where the surfaces are nearly isometric (poses of one
  body), where the extremities may pair tips wrongly and a few landmarks leave
  the map between them free.  A pair an intrinsic symmetry turned over (a left
  paw paired with the right one) is dropped before it blocks the bend
  (:func:`trimmed_fit`).  The caller refines every hypothesis a little and
  keeps the one with the least distortion.
* The same functional map also pairs surface 1's *fine tips*, extremities closer together
  than :data:`SEPARATION` allows (fingertips, toes): on a conformal map they are crowded
  into caps so small that no alignment of the whole sphere tells them apart, and
  neighbouring fingers collapse onto one; the intrinsic spectral descriptors do tell
  them apart where the surfaces are nearly isometric (:class:`FunctionalPairs`).
"""

from dataclasses import dataclass

import numpy as np

import igl
from scipy.optimize import linear_sum_assignment

from ..errors import plural
from ..mesh.operators import vertex_areas
from ..sphere.folds import count_folds
from ..sphere.harmonics import MIRROR, best_rotations, standardized_coefficients
from ..sphere.mobius import mobius_center, mobius_fit, mobius_transform
from .functional_map import spectral_correspondence

#: Degree of the spherical harmonic expansions of the rotation search.
SH_DEGREE = 12

#: Rotation hypotheses the search returns (local maxima of the correlation).
HYPOTHESES = 4

#: Largest number of halvings of the Möbius fit's translation while it folds faces.
MAX_SHRINKS = 10

#: Extremities per surface, at most.
EXTREMITIES = 10

#: Smallest geodesic distance between two extremities, over ``sqrt(area)``.
SEPARATION = 0.15

#: Sources of the average geodesic distance (farthest-point samples).
AGD_SOURCES = 16

#: Vertex rings over which an extremity's average geodesic distance is largest.
AGD_RINGS = 4

#: Concentration ``kappa`` of the bump ``exp(kappa (x . p - 1))`` at each extremity's image.
BUMP_KAPPA = 8.0

#: Largest angle (radians) between the images of two paired extremities.
PAIR_ANGLE = np.radians(45.0)

#: Geodesic farthest-point samples of surface 1 whose partners under the functional map
#: serve as the landmarks of :func:`spectral_start`.
SPECTRAL_PAIRS = 16

#: Smallest geodesic distance between two fine tips, over ``sqrt(area)``: about the
#: spacing of a hand's fingertips (:func:`spectral_pairs`; docs/decisions.md).
FINE_SEPARATION = 0.03

#: Fine tips per surface, at most.
FINE_EXTREMITIES = 30

#: Given landmarks and a functional map's samples together, at most
#: (:func:`spectral_pairs`): a map bent to this many landmarks is more accurate than the
#: functional map's pairs (on the cats: pairs 0.025, the map 0.021 sqrt(area) at them with
#: 32 landmarks; 0.018 and 0.021 with 16: docs/decisions.md).
PAIR_BUDGET = 32

#: A functional map's pair is an outlier of the Möbius fit (:func:`trimmed_fit`) when its
#: image lies farther from its partner's than this many times the pairs' median distance
#: (angles on the sphere) ...
OUTLIER_RATIO = 3.0

#: ... and farther than this (radians): a pair an intrinsic symmetry turned over lands
#: 70-150 degrees off, the others 1-60 degrees (docs/decisions.md).
OUTLIER_ANGLE = np.radians(45.0)


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
        Normalized correlation of the extremity functions (rotation search), in [-1, 1].
    pairs : tuple of two (j,) int64 arrays
        Extremities of surface 1 and of surface 2 paired under this alignment
        (landmarks found, not given).
    """

    U: np.ndarray
    label: str
    score: float = None
    pairs: tuple = (np.zeros(0, np.int64), np.zeros(0, np.int64))


@dataclass
class FunctionalPairs:
    """Vertex pairs of the functional map (:func:`spectral_pairs`).

    Attributes
    ----------
    samples : tuple of two (p,) int64 arrays
        Farthest-point samples of surface 1 and their partners: the landmarks of
        :func:`spectral_start`.
    tips : tuple of two (q,) int64 arrays
        Fine tips of surface 1 (:data:`FINE_SEPARATION`) and their partners, for the
        start kept to refine (the caller checks them against it: the descriptors are right
        only where the surfaces are nearly isometric).  A tip may be a sample too: the
        start kept need not be this functional map's.
    """

    samples: tuple
    tips: tuple


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


def geodesics(V, F):
    """``distances(sources)``: heat-method geodesic distances (n,) from a vertex, or from the
    nearest of several, over ``sqrt(area)``.

    potpourri3d's heat method (Crane, Weischedel, Wardetzky, "Geodesics in heat", TOG 2013)
    on the intrinsic Delaunay triangulation of the intrinsically mollified mesh (Sharp,
    Crane, "A Laplacian for nonmanifold triangle meshes", SGP 2020), factorized once.  On
    the mesh's own cotangent Laplacian (libigl's ``heat_geodesics``) the distances from
    some sources are off by as much as the surface's diameter where the mesh has needle
    triangles (the dinosaur, the cats: docs/decisions.md).
    """
    import potpourri3d as pp3d  # only maps between surfaces need it (start-up time)

    V = np.asarray(V, dtype=np.float64)
    F = np.ascontiguousarray(F, dtype=np.int64)
    scale = np.sqrt(igl.doublearea(V, F).sum() / 2.0)
    solver = pp3d.MeshHeatMethodDistanceSolver(V, F)

    def distances(sources):
        sources = [int(i) for i in np.atleast_1d(np.asarray(sources, dtype=np.int64))]
        if len(sources) == 1:
            return solver.compute_distance(sources[0]) / scale
        return solver.compute_distance_multisource(sources) / scale

    return distances


def geodesic_samples(dist, count):
    """Geodesic farthest-point samples, the first the vertex farthest from vertex 0.

    Parameters
    ----------
    dist : callable
        :func:`geodesics` of the surface.
    count : int

    Returns
    -------
    sources : list of int
    total : (n,) float64 array
        The sum of the distances to the samples (over ``sqrt(area)``).
    """
    d = dist(0)
    sources = [int(np.argmax(d))]
    d = dist(sources[0])
    total = d.copy()
    for _ in range(count - 1):
        sources.append(int(np.argmax(d)))
        di = dist(sources[-1])
        d, total = np.minimum(d, di), total + di
    return sources, total


def farthest_from(dist, seeds, count):
    """``count`` geodesic farthest-point samples continued from the vertices ``seeds``
    ((count,) list of int): each the vertex farthest from the seeds and the samples before
    it.

    Parameters
    ----------
    dist : callable
        :func:`geodesics` of the surface.
    seeds : (k,) int64 array
        ``k >= 1``.
    count : int
    """
    d = dist(seeds)
    picks = []
    for _ in range(count):
        picks.append(int(np.argmax(d)))
        d = np.minimum(d, dist(picks[-1]))
    return picks


def extremities(V, F, count=EXTREMITIES, separation=SEPARATION):
    """Tips of a surface: local maxima of the average geodesic distance, farthest first.

    The average geodesic distance (to :data:`AGD_SOURCES` farthest-point
    samples) is largest at the tips of limbs, head and tail, and intrinsic.  A
    vertex qualifies when it is largest within :data:`AGD_RINGS` rings; they are
    taken in decreasing order, each at least ``separation`` (over ``sqrt(area)``)
    from those taken.

    Returns
    -------
    tips : (e,) int64 array
        Vertex indices, ``e <= count``.
    agd : (n,) float64 array
        The average geodesic distance, over ``sqrt(area)``.
    """
    dist = geodesics(V, F)
    sources, total = geodesic_samples(dist, AGD_SOURCES)
    agd = total / len(sources)
    return tips_of(dist, agd, F, count, separation), agd


def tips_of(dist, agd, F, count, separation):
    """The local maxima of ``agd`` (n,) within :data:`AGD_RINGS` rings of the mesh ``F``,
    largest first, each at least ``separation`` from those taken by the geodesic distances
    ``dist`` (:func:`geodesics`); at most ``count`` ((e,) int64, :func:`extremities`)."""
    A = igl.adjacency_matrix(np.asarray(F, dtype=np.int64)).tocsr()
    R = A.copy()
    for _ in range(AGD_RINGS - 1):
        R = (R + R @ A).tocsr()
    top = np.maximum.reduceat(agd[R.indices], R.indptr[:-1])
    cand = np.flatnonzero(agd >= top)
    tips, near = [], None
    for c in cand[np.argsort(-agd[cand], kind="stable")]:
        if len(tips) == count:
            break
        if near is not None and near[c] < separation:
            continue
        tips.append(int(c))
        dc = dist(c)
        near = dc if near is None else np.minimum(near, dc)
    return np.array(tips, dtype=np.int64)


def bump_coefficients(P, weights, degree=SH_DEGREE):
    """Spherical harmonic coefficients of ``sum_e w_e exp(kappa (x . P_e - 1))``, standardized.

    ``P`` (e, 3) unit vectors, ``weights`` (e,); ``kappa`` = :data:`BUMP_KAPPA`
    (:func:`igl_spheremap.sphere.harmonics.standardized_coefficients`).
    """
    return standardized_coefficients(lambda X: np.exp(BUMP_KAPPA * (X @ P.T - 1.0)) @ weights,
                                     degree)


def paired(P1, P2):
    """One-to-one pairs of the unit vectors ``P1`` (e1, 3) and ``P2`` (e2, 3) closer than
    :data:`PAIR_ANGLE`, by least total angle: ``(i, j)`` index arrays."""
    if P1.shape[0] == 0 or P2.shape[0] == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    ang = np.arccos(np.clip(P1 @ P2.T, -1.0, 1.0))
    i, j = linear_sum_assignment(np.minimum(ang, PAIR_ANGLE + 1.0))
    keep = ang[i, j] < PAIR_ANGLE
    return i[keep].astype(np.int64), j[keep].astype(np.int64)


def rotation_starts(V1, F1, U1, V2, F2, U2, lm1, lm2, count=HYPOTHESES):
    """Alignments of surface 1's area-centred map by SO(3) correlation of the extremity functions.

    Parameters
    ----------
    V1, F1, U1, V2, F2, U2 : arrays
        The two surfaces and their fold-free maps (validated order), both
        Möbius-centred by area (:func:`centred`).
    lm1, lm2 : (k,) int64 arrays
        Given landmark pairs (``k < 3``): paired with the extremities' pairs.
    count : int
        Rotation hypotheses.

    Returns
    -------
    starts : list of Start
        Best correlation first; each rotated, then Möbius-fitted to its pairs
        when there are three or more.
    mirror : float
        Best normalized correlation over improper rotations (surface 1's mirror
        image; not a candidate: both surfaces are oriented outward, so an
        orientation-reversing correspondence would fold every face).
    """
    e1, a1 = extremities(V1, F1)
    e2, a2 = extremities(V2, F2)
    f1 = bump_coefficients(U1[e1], a1[e1])
    f2 = bump_coefficients(U2[e2], a2[e2])
    norm = 4.0 * np.pi  # the correlation of a standardized function with itself
    starts = []
    for c, R in best_rotations(f2, f1, count):
        U = U1 @ R.T
        i, j = paired(U[e1], U2[e2])
        p1 = np.concatenate([lm1, e1[i]])
        p2 = np.concatenate([lm2, e2[j]])
        _, first = np.unique(p1, return_index=True)
        keep = np.sort(first)
        p1, p2 = p1[keep], p2[keep]
        label = (f"area-centred, rotated by correlation {c / norm:.3f} of the extremities "
                 f"({e1.size} and {e2.size}), {i.size} paired")
        if p1.size >= 3:
            fit = landmark_start(F1, U, p1, U2[p2])
            U, label = fit.U, label + "; " + fit.label
        starts.append(Start(U=U, label=label, score=c / norm,
                            pairs=(e1[i].astype(np.int64), e2[j].astype(np.int64))))
    f1m = bump_coefficients(U1[e1] @ MIRROR, a1[e1])
    mirror = best_rotations(f2, f1m, 1)[0][0] / norm
    return starts, float(mirror)


def spectral_pairs(V1, F1, V2, F2, lm1, lm2, count=SPECTRAL_PAIRS):
    """Vertex pairs of a functional map refined by ZoomOut: for :func:`spectral_start`, and
    at surface 1's fine tips.

    :func:`igl_spheremap.uses.functional_map.spectral_correspondence` maps ``count``
    geodesic farthest-point samples of surface 1 (continued from the given landmarks, so
    that the pairs lie where the landmarks are not; no more than :data:`PAIR_BUDGET` less
    the landmarks; with landmarks, a sample that is a fine tip with another within
    :data:`SEPARATION`, a fingertip, is left to the fine tips, whose placement checks it
    against the start kept, while without any it is the functional start's one hold on a
    hand: docs/decisions.md)
    and its fine tips (:func:`tips_of` with :data:`FINE_SEPARATION`, the average geodesic
    distance to those samples) to vertices of surface 2 (fitted again with the given
    landmarks' wave kernel maps where its map contradicts them); each partner is kept once,
    and no pair touches a given landmark.  The
    pairs depend on the surfaces and the landmarks only, not on their spherical maps, so they
    can be found before or beside the maps.

    Parameters
    ----------
    V1, F1, V2, F2 : arrays
        The two surfaces ((n1, 3) float64, (m1, 3) int64, ...; validated order).
    lm1, lm2 : (k,) int64 arrays
        Given landmark pairs (any ``k >= 0``).
    count : int
        Farthest-point samples of surface 1.

    Returns
    -------
    FunctionalPairs
        ``samples``: ``p <= min(count, PAIR_BUDGET - k)`` pairs; ``tips``: pairs at the fine
        tips.
    """
    dist = geodesics(V1, F1)
    sources, total = geodesic_samples(dist, count)
    count = min(count, max(0, PAIR_BUDGET - lm1.size))
    p1 = np.array(sources[:count] if lm1.size == 0 else farthest_from(dist, lm1, count),
                  dtype=np.int64)
    t1 = tips_of(dist, total / len(sources), F1, FINE_EXTREMITIES, FINE_SEPARATION)
    if lm1.size:  # without landmarks the fingertip samples are the hands' only pairs
        p1 = p1[[not _among_tips(dist, a, t1) for a in p1]]
    partners = spectral_correspondence(V1, F1, V2, F2, at=np.concatenate([p1, t1]),
                                       landmarks=(lm1, lm2))
    samples = _once(p1, partners[:p1.size], lm1, lm2)
    return FunctionalPairs(samples=samples, tips=_once(t1, partners[p1.size:], lm1, lm2))


def _among_tips(dist, a, tips):
    """Whether the vertex ``a`` is one of the fine ``tips`` with another within
    :data:`SEPARATION` of it (a fingertip, a toe; bool)."""
    if a not in tips or tips.size < 2:
        return False
    return bool(np.min(dist(int(a))[tips[tips != a]]) < SEPARATION)


def _once(a, b, lm1, lm2):
    """The pairs ``(a, b)`` with each partner ``b`` kept once (its first pair) and none
    touching the vertices ``lm1`` of surface 1 or ``lm2`` of surface 2."""
    _, first = np.unique(b, return_index=True)
    keep = np.sort(first)
    a, b = a[keep], b[keep]
    new = ~np.isin(a, lm1) & ~np.isin(b, lm2)
    return a[new], b[new]


def spectral_start(V1, F1, U1, V2, F2, U2, lm1, lm2, count=SPECTRAL_PAIRS, pairs=None):
    """The alignment of a functional map: surface 1's map Möbius-fitted to pairs of its vertex map.

    The pairs of :func:`spectral_pairs` join the given ones, fix the Möbius fit
    (:func:`landmark_start`) and serve as landmarks.  The descriptors are intrinsic, so this
    start does well where the surfaces are nearly isometric (poses of one body) and poorly
    elsewhere; the caller screens it against the landmarks' own alignment or
    :func:`rotation_starts`.

    Parameters
    ----------
    V1, F1, U1, V2, F2, U2 : arrays
        The two surfaces and their fold-free maps (validated order).
    lm1, lm2 : (k,) int64 arrays
        Given landmark pairs (any ``k >= 0``).
    count : int
    pairs : FunctionalPairs, optional
        :func:`spectral_pairs` of these surfaces and landmarks, when already found.

    Returns
    -------
    Start
    """
    pairs = spectral_pairs(V1, F1, V2, F2, lm1, lm2, count) if pairs is None else pairs
    p1, p2 = pairs.samples
    fit, keep = trimmed_fit(F1, U1, lm1, U2[lm2], p1, U2[p2])
    out = plural(np.count_nonzero(~keep), "dropped as an outlier", "dropped as outliers")
    dropped = f" ({out})" if not keep.all() else ""
    return Start(U=fit.U, label=f"functional map refined by ZoomOut, {keep.sum()} of its "
                 f"pairs{dropped}; " + fit.label, pairs=(p1[keep], p2[keep]))


def trimmed_fit(F1, U1, lm1, targets, p1, p_targets):
    """The Möbius fit (:func:`landmark_start`) to the landmarks and to found pairs, with the
    found pairs it leaves far from their partners dropped one by one.

    A functional map confuses the sides of an intrinsically symmetric body now and then (a
    left paw paired with the right one).  Such a pair keeps the quick bend of a start from
    placing any of its pairs, and the start then loses the screening however good its
    other pairs are.  After the fit to all pairs it lies far from its partner, where the
    others lie near theirs; so the pair farthest from its partner is dropped while it lies
    more than :data:`OUTLIER_RATIO` times the median and more than :data:`OUTLIER_ANGLE`
    away, and the fit is made again (a trimmed least-squares fit; the given landmarks are
    always kept).

    Parameters
    ----------
    F1 : (m1, 3) int64 array
    U1 : (n1, 3) float64 array
        Surface 1's fold-free map.
    lm1 : (k,) int64 array
        Given landmarks of surface 1.
    targets : (k, 3) float64 array
        Their partners' images (unit vectors).
    p1 : (p,) int64 array
        Vertices of surface 1 paired by a found correspondence.
    p_targets : (p, 3) float64 array
        Their partners' images.

    Returns
    -------
    fit : Start
        :func:`landmark_start` of the landmarks and the pairs kept.
    keep : (p,) bool array
        The pairs kept.
    """
    keep = np.ones(p1.size, dtype=bool)
    while True:
        fit = landmark_start(F1, U1, np.concatenate([lm1, p1[keep]]),
                             np.concatenate([targets, p_targets[keep]]))
        if keep.sum() < 4:
            return fit, keep
        at = np.flatnonzero(keep)
        angle = np.arccos(np.clip(np.einsum("ij,ij->i", fit.U[p1[at]], p_targets[at]), -1.0, 1.0))
        worst = int(np.argmax(angle))
        if angle[worst] <= max(OUTLIER_RATIO * np.median(angle), OUTLIER_ANGLE):
            return fit, keep
        keep[at[worst]] = False

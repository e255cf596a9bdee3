"""Which of the functional map's fine-tip pairs the landmark bend places: the crowded ones.

A conformal map crowds a hand's fingertips into a cap far smaller than their distance to
anything else (a human body's, 1e-8 to 1e-7 of it); from any alignment of the whole
sphere, neighbouring fingers collapse onto one, and the distortion stage cannot pull them
apart (its retraction keeps the sphere's crowded faces fold-free, and cuts their steps).
The functional map's descriptors tell the fingertips apart where the surfaces are nearly
isometric (:class:`igl_spheremap.uses.alignment.FunctionalPairs`), so those pairs are
placed as landmarks after the others (:meth:`igl_spheremap.uses.correspondence.
Correspondence.bend_tips`).  Elsewhere a pair, right only to the functional map's
accuracy, would hold the map off, so only crowded tips are taken (docs/decisions.md).
"""

import numpy as np

from ..mesh.operators import SPHERE_AREA
from ..sphere.geodesics import angles
from .alignment import FINE_SEPARATION, geodesics
from .landmark_bend import place, similar_toward, spread_order

#: Largest distance on surface 2 (over ``sqrt(area)``) between a fine tip's partner under the
#: functional map and where the kept start's map puts the tip: a kept start is right at the
#: scale of limbs and hands; a functional map between surfaces that are not nearly isometric,
#: or its left-right flip, is not.  Two fingertips of the woman lie 0.0997-0.1001 from their
#: partners on the woman 15% wider (her palms short along the longer arms; docs/decisions.md),
#: a hand's flip 0.3 or more.
TIP_AGREEMENT = 0.15

#: A fine tip is crowded when another tip or landmark is nearer on the sphere than this
#: times their geodesic distance (surfaces at area ``4 pi``): on the human pose pair of
#: ``benchmarks/correspondence.py`` the fingertips' ratios are 1e-8 to 1e-7, a cat's lone
#: fine tip's 4e-2.
CROWDING = 1e-3


def crowded_tip_pairs(pairs, V1, F1, U1, face, phi, lm1, lm2):
    """The fine-tip pairs a map of surface 1 crowds and agrees with.

    A pair ``(a, b)`` of ``pairs.tips`` is kept when its tip ``a`` is farther than
    :data:`~igl_spheremap.uses.alignment.FINE_SEPARATION` from the landmarks ``lm1``
    (geodesic: two neighbouring fingertips are close in space) and ``b`` is not one of
    ``lm2``; when ``U1`` puts ``a`` within :data:`TIP_AGREEMENT` of ``b`` on surface 2; and
    when ``a`` is crowded (:func:`crowding` below :data:`CROWDING`, among the landmarks and
    the other tips left by the two tests before).

    Parameters
    ----------
    pairs : igl_spheremap.uses.alignment.FunctionalPairs or None
        Its ``tips``: fine tips of surface 1 and their partners on surface 2 (None: no
        pairs).
    V1 : (n1, 3) float64 array
        Surface 1 at area ``4 pi``.
    F1 : (m1, 3) int64 array
    U1 : (n1, 3) float64 array
        Surface 1's map bent to its landmarks (the map the tips are then bent from).
    face : (n1,) int64 array
        Faces of surface 2's map to start the walks from.
    phi : igl_spheremap.uses.sphere_to_surface.SphereToSurface
        Surface 2 (at area ``4 pi``) through its map.
    lm1, lm2 : (k,) int64 arrays
        The landmarks already paired.

    Returns
    -------
    tuple of two (p,) int64 arrays
        The pairs kept, in ``pairs.tips``' order.
    """
    none = np.zeros(0, dtype=np.int64)
    if pairs is None or len(pairs.tips[0]) == 0:
        return none, none
    a, b = (np.asarray(x, dtype=np.int64) for x in pairs.tips)
    unit = np.sqrt(SPHERE_AREA)  # sqrt(area) of the surfaces
    dist = geodesics(V1, F1)
    if lm1.size:
        keep = (dist(lm1)[a] > FINE_SEPARATION) & ~np.isin(b, lm2)
        a, b = a[keep], b[keep]
    if a.size:
        where, w = phi.locate(U1[a], face[a])
        keep = np.linalg.norm(phi.points(where, w) - phi.V2[b], axis=1) < TIP_AGREEMENT * unit
        a, b = a[keep], b[keep]
    others = np.concatenate([lm1, a])
    keep = np.array([crowding(U1, int(i), others, dist) < CROWDING for i in a], dtype=bool)
    return (a[keep], b[keep]) if a.size else (none, none)


def crowding(U, i, others, dist):
    """How much a map crowds vertex ``i`` toward its nearest neighbour among ``others``.

    Parameters
    ----------
    U : (n, 3) float64 array
        A spherical map of a surface at area ``4 pi``.
    i : int
    others : (p,) int64 array
        Vertices (``i`` among them or not).
    dist : callable
        :func:`igl_spheremap.uses.alignment.geodesics` of the surface.

    Returns
    -------
    float
        The least ratio, over ``others`` but ``i``, of the angle from ``i`` on the sphere
        to the geodesic distance on the surface (1 for an isometry at small scale; inf
        without others).
    """
    others = np.asarray(others, dtype=np.int64)
    others = others[others != i]
    if others.size == 0:
        return np.inf
    angle = angles(U[others], np.tile(U[i], (others.size, 1)))
    return float(np.min(angle / (dist(i)[others] * np.sqrt(SPHERE_AREA))))


def placed_tips(V1, F1, U1, lm1, lm2, placed, a, b, U2):
    """Surface 1's map bent on to the tip pairs ``(a, b)`` as well as its landmarks, keeping
    only the tips it places.

    Each group of tips is first turned and scaled about its nearest placed landmark
    (:func:`igl_spheremap.uses.landmark_bend.similar_toward`; given landmarks crowded with
    the tips join the group), then all are placed, the landmarks first
    (:func:`~igl_spheremap.uses.landmark_bend.place`, which bends crowded caps locally).  A
    tip whose group the similarity cannot move, or that the bend does not place, is dropped:
    the pairs are hypotheses, and one left to a spring in a crowded cap tangles it.  If a
    landmark placed before is not placed again, ``U1`` is returned without tips.

    Parameters
    ----------
    V1, F1 : (n1, 3) float64 array, (m1, 3) int64 array
        Surface 1 (the bend's order is farthest-point on it, landmarks before tips:
        :func:`~igl_spheremap.uses.landmark_bend.spread_order`).
    U1 : (n1, 3) float64 array
        Surface 1's fold-free map, bent to the landmarks.
    lm1, lm2 : (k,) int64 arrays
        Landmark pairs (surface 1, surface 2).
    placed : (k,) bool array
        Those on their targets.
    a, b : (q,) int64 arrays
        Tip pairs (:func:`crowded_tip_pairs`).
    U2 : (n2, 3) float64 array
        Surface 2's map.

    Returns
    -------
    U : (n1, 3) float64 array
        Fold-free.
    lm1, lm2 : (k + p,) int64 arrays
        The landmarks followed by the ``p`` tips placed.
    placed : (k + p,) bool array
    """
    k = lm1.size
    L1, L2 = np.concatenate([lm1, a]), np.concatenate([lm2, b])
    P = np.concatenate([placed, np.zeros(len(a), dtype=bool)])
    U, moved = similar_toward(F1, U1, L1, U2[L2], P)
    keep = np.concatenate([np.ones(k, dtype=bool), moved[k:]])
    L1, L2, P = L1[keep], L2[keep], (P & ~moved)[keep]
    if L1.size == k:
        return U1, lm1, lm2, placed
    order = np.concatenate([spread_order(V1[L1[:k]]), k + spread_order(V1[L1[k:]])])
    U, P = place(F1, U, L1, U2[L2], order, P)
    if np.any(placed & ~P[:k]):
        return U1, lm1, lm2, placed
    keep = np.concatenate([np.ones(k, dtype=bool), P[k:]])
    return U, L1[keep], L2[keep], P[keep]

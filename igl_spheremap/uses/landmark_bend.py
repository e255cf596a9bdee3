"""Bending surface 1's spherical map until its landmarks sit on their targets, fold-free.

Unlike :func:`igl_spheremap.landmark_map`, which returns the unbent map when the
landmarks cannot all be reached without folds, :func:`place` keeps what it
reached: when the smooth deformation of the sphere
(:func:`igl_spheremap.uses.landmarks.deformed`) cannot carry every landmark to
its target at once, the landmarks are placed coarse to fine: first the
:data:`FIRST_STAGE` spread farthest apart on surface 1, then twice as many (the
ones placed stay), and so on, so that the later landmarks start close to their
targets; a stage that cannot be completed is retried one landmark at a time;
a landmark still unplaced whose neighbourhood is crowded is then bent into place
inside its own cap, spread over a hemisphere by a Möbius dilation
(:func:`local_bend`); and one that still cannot be placed is left where it is
(the caller's distortion stage pulls it on by a spring and places it later).
"""

import numpy as np

from ..mesh.frames import tangent_bases
from ..sphere.chart import disk_patch
from ..sphere.folds import count_folds
from ..sphere.geodesics import angles
from ..sphere.mobius import dilation
from .landmarks import MAX_UNTANGLED, deformed

#: Landmarks of the first stage of the coarse-to-fine bend (then doubled per stage).
FIRST_STAGE = 4

#: :func:`similar_toward`: the similarity acts inside twice the angle of its group's farthest
#: point or target from the centre and fades out over at least ``2 |log scale| + FADE_SPAN``
#: e-folds of the angle beyond.
FADE_SPAN = 1.0

#: :func:`similar_toward`: the fade ends by half the angle to the nearest other placed
#: landmark (which stays where it is), and by this angle (radians) at most.
FADE_OUT = 0.5

#: :func:`local_bend`: radius of the cap, in multiples of the larger of the landmark's angle to
#: its target and to the nearest other landmark (both then lie well inside it).
LOCAL_CAP = 8.0

#: :func:`local_bend`: widest cap (radians); a landmark whose cap would be wider is not
#: crowded, and the deformation of the whole sphere has already had its chance.
LOCAL_CAP_MAX = 0.5

#: ``max_untangled`` of the coarse-to-fine bend's deformations and of the local bends
#: (:func:`igl_spheremap.uses.landmarks.deformed`): their many attempts that cannot succeed
#: would otherwise spend most of their time untangling.
RETRY_UNTANGLED = 0

#: :func:`place`: a landmark flagged as placed counts as on its target when its image is
#: within this chordal distance of it on the unit sphere.  The bends put a placed landmark on
#: its target to the bit or to the rounding of a Möbius dilation and back (2e-13 measured);
#: a flag carried over from another map of the same landmarks is off by far more.
ON_TARGET_TOL = 1e-9


def spread_order(P):
    """Order of the points ``P`` (k, 3) by farthest-point sampling from the first one ((k,) int64)."""
    if P.shape[0] == 0:
        return np.zeros(0, dtype=np.int64)
    return farthest_points(P, [0], P.shape[0])


def farthest_points(V, first, count):
    """``first`` followed by farthest-point samples of the points ``V`` in space ((count,) int64).

    Parameters
    ----------
    V : (n, 3) float64 array
    first : (k,) int64 array
        Distinct indices kept first (e.g. landmarks); with none, the samples start at 0.
    count : int
        Number of indices returned (at most ``n``).
    """
    picks = [int(i) for i in first] or [0]
    d = np.full(V.shape[0], np.inf)
    for i in picks:
        d = np.minimum(d, np.linalg.norm(V - V[i], axis=1))
    while len(picks) < min(count, V.shape[0]):
        picks.append(int(np.argmax(d)))
        d = np.minimum(d, np.linalg.norm(V - V[picks[-1]], axis=1))
    return np.array(picks, dtype=np.int64)


def place(F, U, lm, targets, order, placed=None, stages=True, quick=False):
    """Surface 1's map bent so that as many landmarks as possible sit exactly on their targets.

    Parameters
    ----------
    F : (m1, 3) int64 array
    U : (n1, 3) float64 array
        Fold-free map.
    lm : (k,) int64 array
        Landmark vertices.
    targets : (k, 3) float64 array
        Unit vectors.
    order : (k,) int64 array
        Positions in ``lm`` from coarse to fine (:func:`spread_order` of the
        landmarks on surface 1).
    placed : (k,) bool array, optional
        Landmarks already on their targets (they stay there).  A flag whose landmark is not
        on its target in ``U`` (within :data:`ON_TARGET_TOL`) is dropped: it describes
        another map.
    stages : bool
        False: only the deformation that moves every landmark at once, without untangling
        (a quick first look, e.g. to screen alignments); nothing is placed when it cannot be
        completed.
    quick : bool
        With ``stages``: the stages alone, without what makes a bend that fails slow (the
        first deformation of every landmark at once with local untangling, the landmarks of
        a failed stage tried one by one, the local bends); to screen a start whose quick
        first look has just failed.

    Returns
    -------
    U : (n1, 3) float64 array
        Fold-free map.
    placed : (k,) bool array
        Landmarks on their targets.
    """
    placed = np.zeros(lm.size, dtype=bool) if placed is None else placed & on_targets(U[lm], targets)
    if not (stages and quick):
        Y, t = deformed(F, U, lm, targets, MAX_UNTANGLED if stages else RETRY_UNTANGLED)
        if t == 1.0:
            return Y, np.ones(lm.size, dtype=bool)
    if not stages:
        return U, placed
    done = [int(j) for j in np.flatnonzero(placed)]
    todo = [int(j) for j in order if not placed[j]]
    size, tried = min(FIRST_STAGE, len(todo)), set()
    while todo:
        new = [j for j in todo[:size] if j not in tried]
        tried.update(new)
        Z, t = deformed(F, U, lm[done + new], targets[done + new], RETRY_UNTANGLED)
        if t == 1.0:
            U, done = Z, done + new
        elif len(new) > 1 and not quick:  # a stage of one was that landmark's own attempt
            for j in new:
                Z, t = deformed(F, U, lm[done + [j]], targets[done + [j]], RETRY_UNTANGLED)
                if t == 1.0:
                    U, done = Z, done + [j]
        if size >= len(todo):
            break
        size = min(2 * size, len(todo))
    placed[done] = True
    if quick:
        return U, placed
    for j in order:
        if not placed[j]:
            U, placed = local_bend(F, U, lm, targets, placed, j)
    return U, placed


def on_targets(P, targets):
    """Whether each point of ``P`` (k, 3) lies within :data:`ON_TARGET_TOL` of its row of
    ``targets`` (k, 3) ((k,) bool)."""
    return np.linalg.norm(P - targets, axis=1) <= ON_TARGET_TOL


def local_bend(F, U, lm, targets, placed, j):
    """``U`` bent inside a cap around landmark ``j`` until ``j`` sits on its target, or
    unchanged.

    The deformation of the whole sphere (:func:`~igl_spheremap.uses.landmarks.deformed`)
    cannot resolve landmarks crowded into a cap far smaller than their distance to the
    rest (a hand's fingertips on a conformal map of a body: 1e-8 of it).  Here the cap of
    radius ``R`` (:data:`LOCAL_CAP` times the larger of ``j``'s angle to its target and to
    the nearest other landmark; at most :data:`LOCAL_CAP_MAX`) is spread over a hemisphere
    by the Möbius dilation about ``j`` (:func:`igl_spheremap.sphere.mobius.dilation`,
    ``tan(R / 2)`` to 1), deformed there with its boundary and the other landmarks inside
    held (the unplaced ones with targets inside the cap carried to them as well), and
    brought back by the inverse dilation: conformal both ways, so the cap's triangles keep
    their orientation and the map outside the cap is untouched.

    Parameters
    ----------
    F : (m, 3) int64 array
    U : (n, 3) float64 array
        Fold-free map (unit rows).
    lm : (k,) int64 array
        Landmark vertices.
    targets : (k, 3) float64 array
        Unit vectors.
    placed : (k,) bool array
        Landmarks on their targets (held).
    j : int
        Position in ``lm`` of the landmark to place.

    Returns
    -------
    U : (n, 3) float64 array
        Fold-free.
    placed : (k,) bool array
        With ``j`` (and the landmarks carried with it) set when the bend succeeded.
    """
    c = U[lm[j]]
    others = np.delete(U[lm], j, axis=0)
    gap = angles(others, np.tile(c, (len(others), 1))).min() if len(others) else np.pi
    radius = LOCAL_CAP * max(gap, float(angles(c[None], targets[j][None])[0]))
    if not 0.0 < radius <= LOCAL_CAP_MAX:
        return U, placed
    inside = angles(U, np.tile(c, (U.shape[0], 1))) < radius  # not by dot products: they round
    patch = disk_patch(F, np.flatnonzero(inside[F].all(axis=1)), np.zeros(U.shape[0], dtype=bool))
    if patch is None:
        return U, placed
    verts, Fl, boundary = patch
    factor = 1.0 / np.tan(0.5 * radius)
    Z = dilation(U[verts], c, factor)
    local = np.full(U.shape[0], -1, dtype=np.int64)
    local[verts] = np.arange(verts.size)
    carried = [i for i in range(len(lm)) if not placed[i] and local[lm[i]] >= 0
               and not boundary[local[lm[i]]]
               and angles(targets[i][None], c[None])[0] < 0.5 * radius]
    held = np.flatnonzero(boundary | np.isin(verts, lm[np.setdiff1d(np.arange(len(lm)), carried)]))
    pins = np.concatenate([held, local[lm[carried]]])
    Q = np.vstack([Z[held], dilation(targets[carried], c, factor)])
    Y, t = deformed(Fl, Z, pins, Q, RETRY_UNTANGLED)
    if t < 1.0:
        return U, placed
    out = U.copy()
    out[verts[~boundary]] = dilation(Y[~boundary], c, 1.0 / factor)
    out[verts[held]] = U[verts[held]]  # bit for bit, not through the round trip
    out[lm[carried]] = targets[carried]
    if count_folds(F, out):
        return U, placed
    placed = placed.copy()
    placed[carried] = True
    return out, placed


def similar_toward(F, U, lm, targets, placed):
    """``U`` with the landmarks not yet placed brought toward their targets by similarities
    about placed landmarks, each faded out around its centre; fold-free by construction.

    Each unplaced landmark joins the placed landmark nearest to its image.  About that centre
    ``c``, in polar coordinates ``(r, theta)`` on the sphere (``r`` the angle from ``c``),
    the group's images and targets give the least-squares scale ``lambda`` (the mean of
    ``log(r_target / r)``) and turn ``phi`` (the circular mean of ``theta_target - theta``),
    and every vertex moves by ``(r, theta) -> (r lambda^s, theta + s phi)``: ``s = 1``
    inside ``r_in`` (twice the group's largest angle), ``s = 0`` beyond ``r_out``
    (:data:`FADE_OUT`, or half the angle to the nearest other placed landmark), linear in
    ``log r`` between.  In ``(log r, theta)`` its Jacobian is
    ``[[1 + s' log lambda, 0], [s' phi, 1]]``, of determinant
    ``1 - log lambda / log(r_out / r_in)``, positive when the fade spans more than
    ``|log lambda|`` e-folds (:data:`FADE_SPAN` more than twice that are asked for): a
    spiral similarity inside, the identity outside, orientation-preserving between.

    On a conformal map the tips of fingers or toes sit in a cap far smaller than its
    distance to anything else, and a smooth deformation that carries each tip to its target
    (:func:`igl_spheremap.uses.landmarks.deformed`) must turn and scale the cap within it,
    which folds the faces around; the spiral similarity does that part across the wide
    annulus the crowding leaves, and the tips start near their targets.  Where another placed
    landmark crowds the centre (two given fingertips of one hand) the annulus is too narrow:
    the centre then joins the group, leaving its target, and the nearest placed landmark
    becomes the centre, until the annulus is wide enough.  A group whose move folds faces
    (rounding) is left as it is.

    Parameters
    ----------
    F : (m, 3) int64 array
    U : (n, 3) float64 array
        Fold-free map (unit rows).
    lm : (k,) int64 array
        Landmark vertices.
    targets : (k, 3) float64 array
        Unit vectors.
    placed : (k,) bool array
        Landmarks on their targets: the centres, which stay.

    Returns
    -------
    U : (n, 3) float64 array
        Fold-free.
    moved : (k,) bool array
        The landmarks a similarity moved: unplaced ones, and placed ones that joined a group
        (now off their targets).
    """
    centres, tips = np.flatnonzero(placed), np.flatnonzero(~placed)
    moved = np.zeros(len(lm), dtype=bool)
    if centres.size == 0 or tips.size == 0:
        return U, moved
    chords = np.linalg.norm(U[lm[tips]][:, None] - U[lm[centres]][None], axis=2)
    near = centres[np.argmin(chords, axis=1)]  # not by dot products: they round to 1 there
    free = placed.copy()  # placed landmarks not yet in a group
    for c in np.unique(near):
        group, Y = list(tips[near == c]), None
        while True:
            if not free[c]:  # joined an earlier group: the nearest free one instead
                c = _nearest(U, lm, np.flatnonzero(free), U[lm[c]])
                if c is None:
                    break
            others = np.flatnonzero(free)
            others = others[others != c]
            r_out = FADE_OUT
            if others.size:
                gaps = angles(U[lm[others]], np.tile(U[lm[c]], (others.size, 1)))
                r_out = min(r_out, 0.5 * float(gaps.min()))
            Y = _spiral_similarity(U, U[lm[c]], U[lm[group]], targets[group], r_out)
            if Y is not None or others.size == 0:
                break
            group.append(c)  # crowded among placed landmarks: the centre joins the group
            free[c] = False
        if Y is not None and count_folds(F, Y) == 0:
            U = Y
            moved[group] = True
        free[group] = placed[group] & ~moved[group]
    return U, moved


def _nearest(U, lm, among, x):
    """The position in ``lm`` (of ``among``) whose image is nearest to ``x``, or None."""
    if among.size == 0:
        return None
    return int(among[np.argmin(np.linalg.norm(U[lm[among]] - x, axis=1))])


def _spiral_similarity(U, c, P, Q, r_out):
    """:func:`similar_toward`'s move about ``c`` for the images ``P`` and targets ``Q``, or None
    where the annulus up to ``r_out`` is too narrow."""
    E = tangent_bases(c[None])[0]

    def polar(X):
        d = X - c
        return angles(X, np.tile(c, (len(X), 1))), np.arctan2(d @ E[:, 1], d @ E[:, 0])

    (rp, tp), (rq, tq) = polar(P), polar(Q)
    if np.any(rp <= 0) or np.any(rq <= 0):
        return None
    log_scale = float(np.mean(np.log(rq / rp)))
    turn = float(np.angle(np.mean(np.exp(1j * (tq - tp)))))
    r_in = 2.0 * max(rp.max(), rq.max())
    span = np.log(r_out / r_in) if r_out > r_in else 0.0
    if span < 2.0 * abs(log_scale) + FADE_SPAN:
        return None
    r, theta = polar(U)
    inside = (r > 0) & (r < r_out)
    s = np.clip(np.log(r_out / r[inside]) / span, 0.0, 1.0)
    r2, t2 = r[inside] * np.exp(s * log_scale), theta[inside] + s * turn
    out = np.array(U, dtype=np.float64)
    out[inside] = (np.cos(r2)[:, None] * c
                   + np.sin(r2)[:, None] * (np.cos(t2)[:, None] * E[:, 0]
                                            + np.sin(t2)[:, None] * E[:, 1]))
    return out

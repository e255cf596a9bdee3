"""The stages of :func:`igl_spheremap.surface_map` after the two conformal maps.

:class:`Correspondence` holds both surfaces (validated order, scaled to area
``4 pi``), surface 2's fixed map and the landmark pairs, and runs alignment,
landmark bend and the distortion stage, from each start the alignment offers.
"""

import time

import numpy as np

from ..errors import plural
from ..folding.result import build_result
from ..mesh.operators import vertex_areas
from .alignment import (PAIR_BUDGET, Start, centred, geodesics, landmark_start,
                        rotation_starts, spectral_pairs, spectral_start)
from .coarse_to_fine import coarse_level, coarse_stage
from .descriptors import DescriptorTerm, disk_radius, landmark_harmonics
from .fine_tips import crowded_tip_pairs, placed_tips
from .landmark_bend import place, spread_order
from .side_by_side import side_by_side
from .sphere_to_surface import SphereToSurface
from .surface_arap import (SurfaceARAP, auto_robust_scale, inverse_distortion, piecewise_rigid,
                           refine, to_sphere_scale)

#: Largest number of iterations of the distortion stage.
ITERATIONS = 30

#: Iterations of the distortion stage that each start gets before the best one is kept.
SCREEN_ITERATIONS = 5

#: Stiffness of the landmark springs (surfaces scaled to area ``4 pi``): ``mode="soft"``'s
#: default, and in ``mode="hard"`` the pull on landmarks the bend could not place.
SPRING = 1e3

#: ``mode="hard"``: largest landmark distance over ``sqrt(area)`` that counts as met (rounding).
HARD_TOL = 1e-9

#: ``mode="soft"``: default largest landmark distance over ``sqrt(area)`` that counts as met.
SOFT_TOL = 1e-2

#: Weight of the proximal term ``A_i |X_i - X_i^current|^2`` of the distortion stage's steps.
PROXIMAL = 1e-2

#: The default ``descriptor_weight`` of :func:`igl_spheremap.surface_map` with at least
#: :data:`DESCRIPTOR_MIN_LANDMARKS` landmark pairs (docs/decisions.md).
DESCRIPTOR_WEIGHT = 300.0

#: Geodesic radius (over ``sqrt(area)``) of the disk about a found pair in which
#: :meth:`Correspondence.worst_pair` averages the screened map's distortion.
PAIR_DISK = 0.1

#: Fewest landmark pairs for which :func:`igl_spheremap.surface_map` turns the descriptor term
#: on by default: the harmonic coordinates of a few landmarks say little beyond the Möbius fit
#: to them, and pull a pair that is not conformally equivalent toward it (docs/decisions.md).
DESCRIPTOR_MIN_LANDMARKS = 8

#: Fraction of the descriptor term's weight the last distortion stage keeps where the map before
#: it is not near-isometric (:meth:`Correspondence.last_stage`; docs/decisions.md).
LAST_STAGE_DESCRIPTORS = 0.1


def descriptor_words(fraction):
    """How a stage with the descriptor term at ``fraction`` (float) of its weight is described in
    messages: ``""`` at 1, ``", descriptor term off"`` at 0."""
    if fraction == 1.0:
        return ""
    return f", descriptor term at {fraction:g} of its weight" if fraction else ", descriptor term off"


def default_descriptor_weight(k):
    """The descriptor weight :func:`igl_spheremap.surface_map` uses for ``k`` landmark pairs
    when none is given: :data:`DESCRIPTOR_WEIGHT` from :data:`DESCRIPTOR_MIN_LANDMARKS` on, else 0."""
    return DESCRIPTOR_WEIGHT if k >= DESCRIPTOR_MIN_LANDMARKS else 0.0


class Correspondence:
    """Surface 1's map from alignment to the distortion stage (see the module doc).

    Parameters
    ----------
    problem1, problem2 : igl_spheremap.folding.problem.MapProblem
        The two surfaces' conformal-map problems (validated meshes, Laplacians, areas).
    map1, map2 : SphericalMapResult
        Their conformal maps.
    l1, l2 : (k,) int64 arrays
        Landmark pairs, validated numbering.
    mode : {"hard", "soft"}
    weight : float
        Stiffness of the landmark springs.
    say : callable
        ``say(text)`` before each stage.
    descriptor_weight : float
        Weight of the distortion stage's descriptor term (0: none;
        :class:`igl_spheremap.uses.descriptors.DescriptorTerm`).
    coarse_levels : tuple of int
        Vertex counts of the coarse levels of the distortion stage, coarsest first
        (:mod:`igl_spheremap.uses.coarse_to_fine`; empty: none).
    workers : int
        Processes that screen the aligned starts side by side
        (:func:`igl_spheremap.uses.side_by_side.side_by_side`; 1: all in this process, with
        the same result).
    robust_scale : float, "auto" or None
        The last distortion stage charges the distortion by the robust penalty of this scale
        (:func:`igl_spheremap.uses.surface_arap.robust_penalty`); ``"auto"``: where the map
        before it is near-isometric (:func:`~igl_spheremap.uses.surface_arap.auto_robust_scale`)
        and the penalty's map piecewise rigid (:meth:`last_stage`); None: plain ARAP.
    """

    def __init__(self, problem1, map1, problem2, map2, l1, l2, mode, weight, say,
                 descriptor_weight=0.0, coarse_levels=(), workers=1, robust_scale=None):
        self.problem1, self.map1, self.problem2, self.map2 = problem1, map1, problem2, map2
        self.l1, self.l2, self.mode, self.weight, self.say = l1, l2, mode, weight, say
        self.workers, self.robust_scale = workers, robust_scale
        self.descriptor_weight = descriptor_weight
        self.coarse_levels = tuple(int(c) for c in coarse_levels)
        F1, F2 = problem1.F, problem2.F
        self.V1s = to_sphere_scale(problem1.mesh.V, F1)
        self.V2s = to_sphere_scale(problem2.mesh.V, F2)
        self.U1 = problem1.mesh.from_input(map1.U)
        self.U2 = problem2.mesh.from_input(map2.U)
        self.phi = SphereToSurface(self.U2, F2, self.V2s)
        self.descriptors = {}
        self.placed = None  # the given landmarks placed exactly, once run
        self.deferred = None  # the start run() left after its bend, and the notes so far
        self.spectral_pairs = None  # the functional map's pairs, once found

    def in_domain(self, map1, map2):
        """The same problem with other fold-free spherical maps of the two surfaces as the
        common domain (a new :class:`Correspondence`)."""
        other = Correspondence(self.problem1, map1, self.problem2, map2, self.l1, self.l2,
                               self.mode, self.weight, self.say, self.descriptor_weight,
                               self.coarse_levels, self.workers, self.robust_scale)
        # the functional map's pairs and the descriptor terms depend on the surfaces only
        other.spectral_pairs, other.descriptors = self.spectral_pairs, self.descriptors
        return other

    def __getstate__(self):
        # sent to a worker process (:meth:`run`'s screening): the caller's progress callback
        # need not pickle, and a worker reports no stages
        return dict(self.__dict__, say=_quiet)

    def own_starts(self):
        """The aligned starts that need no functional map, and a note on them: the Möbius fit to
        the landmarks (three or more) or rotations found by correlation of the extremities
        (fewer)."""
        F1, F2 = self.problem1.F, self.problem2.F
        if self.l1.size >= 3:
            starts = [landmark_start(F1, self.U1, self.l1, self.U2[self.l2])]
            return starts, f"the Möbius fit to the {self.l1.size} landmarks"
        self.U1 = centred(self.V1s, F1, self.U1)
        self.U2 = centred(self.V2s, F2, self.U2)
        self.phi = SphereToSurface(self.U2, F2, self.V2s)
        starts, mirror = rotation_starts(self.V1s, F1, self.U1, self.V2s, F2, self.U2,
                                         self.l1, self.l2)
        scores = ", ".join(f"{s.score:.3f}" for s in starts)
        return starts, (f"{len(starts)} rotations of the area-centred conformal map by "
                        f"correlation of the extremities ({scores}; mirror image {mirror:.3f})")

    def spectral_start(self, pairs=None, timings=None):
        """The start of a functional map, whose pairs join the given ones
        (:func:`igl_spheremap.uses.alignment.spectral_start`; after :meth:`own_starts`), from
        :attr:`spectral_pairs` or else the job ``pairs`` (waited for); its seconds added to
        ``timings["align"]``."""
        t = time.perf_counter()
        start = spectral_start(self.V1s, self.problem1.F, self.U1, self.V2s, self.problem2.F,
                               self.U2, self.l1, self.l2, pairs=self.functional_pairs(pairs))
        if timings is not None:
            timings["align"] += time.perf_counter() - t
        return start

    def functional_pairs(self, pairs=None):
        """:attr:`spectral_pairs`, found first (:func:`~.alignment.spectral_pairs`), or taken
        from the job ``pairs`` (waited for), where not yet known."""
        if self.spectral_pairs is None:
            self.spectral_pairs = (pairs.result() if pairs is not None else spectral_pairs(
                self.V1s, self.problem1.F, self.V2s, self.problem2.F, self.l1, self.l2))
        return self.spectral_pairs

    def problem(self, cand, level=None, descriptors=1.0, robust=None):
        """The distortion stage's :class:`SurfaceARAP` for the landmarks of ``cand`` (see
        :meth:`candidate`), on surface 1 or on a coarse level ``(S, Fc)`` of it
        (:func:`igl_spheremap.uses.coarse_to_fine.coarse_level`, the landmarks ``S[:k]``),
        with the descriptor term at ``descriptors`` (float) of its weight (0: without), robust
        if ``robust`` is set."""
        lm1, lm2, placed = cand["lm1"], cand["lm2"], cand["placed"]
        V, F, at = self.V1s, self.problem1.F, lm1
        if level is not None:
            V, F, at = self.V1s[level[0]], level[1], np.arange(lm1.size)
        fixed = np.zeros(V.shape[0], dtype=bool)
        pulled = np.ones(lm1.size, dtype=bool)
        if self.mode == "hard":
            fixed[at[placed]] = True
            pulled = ~placed
        springs = (at[pulled], self.V2s[lm2[pulled]], self.weight)
        term = self.descriptor(placed[:self.l1.size]) if descriptors else None
        if term is not None and descriptors != 1.0:
            term = term.weighted(descriptors)
        if term is not None and level is not None:
            term = term.restricted(level[0], vertex_areas(V, F))
        # SuperLU for the small coarse levels: sksparse-minimal's CHOLMOD corrupted the heap
        # once on a 13-vertex level (docs/decisions.md)
        return SurfaceARAP(V, F, self.phi, fixed, springs, PROXIMAL, term,
                           "direct" if level is None else "superlu", rescale=level is None,
                           orient=level is None, robust=robust)

    def descriptor(self, placed):
        """The :class:`DescriptorTerm` of the given landmark pairs that sit on their targets
        (``placed`` (k,) bool), or None (weight 0, or none placed).  A pair that is only pulled
        by a spring would make its descriptor contradict the map near it."""
        if self.descriptor_weight <= 0 or not placed.any():
            return None
        key = tuple(np.flatnonzero(placed))
        if key not in self.descriptors:
            F1, F2, l1, l2 = self.problem1.F, self.problem2.F, self.l1[placed], self.l2[placed]
            r = disk_radius(self.V1s, F1, self.V2s, F2)
            d1 = landmark_harmonics(self.V1s, F1, l1, r)
            d2 = landmark_harmonics(self.V2s, F2, l2, r)
            self.descriptors[key] = DescriptorTerm(d1, d2, self.V2s, F2, vertex_areas(self.V1s, F1),
                                                   self.descriptor_weight)
        return self.descriptors[key]

    def inverse_distortion(self, U):
        """:func:`.surface_arap.inverse_distortion` of surface 1's map ``U`` (n1, 3) (float)."""
        return inverse_distortion(self.V1s, self.problem1.F, U, self.V2s, self.problem2.F, self.U2)

    def placed_on_targets(self, U, cand, stages=True, quick=False):
        """``(U, placed)``: ``U`` bent until the landmarks of ``cand`` sit on their targets where
        that is possible without folds (:func:`igl_spheremap.uses.landmark_bend.place`).

        The given landmarks come first: they are what the caller asked for, the pairs a
        start's own alignment found are hypotheses, and a pair bent among them can take the
        room a given landmark needs (docs/decisions.md).  With ``stages``, the given landmarks
        by ``place``'s whole staged bend, then the found pairs from there by its staged bend
        (``quick``: without retries one by one and local bends, to screen a start: a wrong
        pair fails slowly).  With ``stages`` False, only the all-at-once deformation, of every
        landmark, and where that fails for a start with pairs of its own, of the given
        landmarks and then of all from there, so that the screening scores the start with
        the given landmarks placed, not on springs alone."""
        lm1, lm2 = cand["lm1"], cand["lm2"]
        if lm1.size == 0:
            return U, np.zeros(0, dtype=bool)
        F, targets, order, k = self.problem1.F, self.U2[lm2], cand["order"], self.l1.size
        before = np.zeros(lm1.size, dtype=bool) if cand.get("placed") is None else cand["placed"]
        if stages:  # the given landmarks' bend from the start's map is kept for the finish
            from_start = U is getattr(cand.get("start"), "U", None)
            bent = cand.get("given_bend") if from_start else None
            if bent is None:
                bent = (U, before[:0]) if k == 0 else place(F, U, lm1[:k], targets[:k],
                                                           order[order < k], before[:k])
                if from_start:
                    cand["given_bend"] = bent
            Y, given = bent
            if lm1.size == k:
                return Y, given
            return place(F, Y, lm1, targets, order, np.concatenate([given, before[k:]]),
                         quick=quick)
        Y, placed = place(F, U, lm1, targets, order, before, False)
        if placed.any() or not 0 < k < lm1.size:
            return Y, placed
        Y, given = place(F, U, lm1[:k], targets[:k], order[order < k], None, False)
        if not given.all():
            return U, placed
        first = np.concatenate([given, np.zeros(lm1.size - k, dtype=bool)])
        Z, placed = place(F, Y, lm1, targets, order, first, False)
        return (Z, placed) if placed.all() else (Y, first)

    def run(self, iterations, timings, defer=False, pairs=None):
        """Align, bend and refine; the final map (validated order), the stages and notes.

        Every start (:meth:`own_starts`, :meth:`spectral_start`) gets
        :data:`SCREEN_ITERATIONS` iterations of the distortion stage, the starts side by side
        in up to ``workers`` processes (:meth:`screen`), and the one of least distortion both
        ways (the stage's energy plus :meth:`inverse_distortion`) gets the rest
        (:meth:`finish`).  That score charges a start the springs of the pairs its own alignment
        found and the quick bend could not place, hypotheses that may be right but not all
        placeable at once.  So among the starts whose quick bend placed every given landmark,
        the one of least :meth:`given_score` (without those springs) is a rival: if it is
        another start, both are finished side by side and the one :meth:`final_rank` prefers is
        kept (docs/decisions.md).  The starts are screened without the coarse levels.  The
        rotations are bent by the all-at-once deformation only (the staged bend of a wrong
        alignment's pairs fails slowly); the Möbius fit and the functional map's start, where
        that fails, by the staged bend (the given landmarks first and whole, the found pairs
        quickly: :meth:`placed_on_targets`), so that every start is scored with the given
        landmarks placed where they can be; the functional map's start, whose pairs are
        right but for a few, is screened once more without its pair of most distortion
        (:meth:`without_worst_pair`).  With :data:`~.alignment.PAIR_BUDGET` landmarks or more
        the functional map has no pairs to add and only its fine tips are used.

        ``pairs``: a :class:`~.side_by_side.Background` job of the functional map's pairs
        (:func:`~.alignment.spectral_pairs`), waited for only when a start needs it.

        With ``defer`` (``mode="hard"``), a single kept start whose whole bend leaves a given
        landmark unplaced is not finished: ``run`` returns None, :attr:`placed` says what the
        bend placed, and :meth:`resume` finishes it when the caller needs it.  The caller
        (:func:`igl_spheremap.surface_map`) first tries the landmarks on other maps of the
        surfaces, since such a landmark usually fails on the domain (docs/decisions.md).
        """
        t = time.perf_counter()
        self.say("aligning surface 1's map to surface 2's")
        own, note = self.own_starts()
        notes = [note + (" and the start of a functional map" if self.l1.size < PAIR_BUDGET
                         else "")]
        timings["align"] = time.perf_counter() - t
        timings["landmarks"] = timings["refine"] = 0.0
        screens = self.screen(own, pairs, iterations, timings)
        if len(screens) > len(own) and screens[-1][2] > min(s[2] for s in screens):
            screens[-1] = self.without_worst_pair(screens[-1], iterations, timings)
        scores = [s[2] for s in screens]
        notes.append("starts screened by their distortion both ways: "
                     + ", ".join(f"{v:.4g}" for v in scores))
        best = screens[int(np.argmin(scores))][0]
        k = self.l1.size
        given = [s[3] if s[0]["placed"][:k].all() else np.inf for s in screens]
        rival = screens[int(np.argmin(given))][0] if np.isfinite(min(given)) else best
        if rival is best:
            if not self.finish(best, iterations, timings, defer):
                self.deferred = best, notes
                self.placed = best["placed"][:k].copy()
                return None
        else:
            notes.append("without the springs of their own pairs, where every given landmark "
                         "was placed: " + ", ".join(f"{v:.4g}" for v in given)
                         + "; both starts kept were finished")
            if self.workers > 1:
                self.say("finishing the two starts the scores disagree on, side by side")
            done = side_by_side([(finished, self, c, iterations) for c in (best, rival)],
                                self.workers)
            for _, spent in done:
                add_timings(timings, spent)
            ranks = [self.final_rank(c) for c, _ in done]
            notes.append("finished: " + ", ".join(f"{plural(-a, 'given landmark')} placed, {b:.4g}"
                                                  for a, b in ranks))
            best = done[0][0] if ranks[0] <= ranks[1] else done[1][0]
        return self.outcome(best, notes)

    def screen(self, own, pairs, iterations, timings):
        """The screening (:func:`screened`) of the starts ``own`` and of the functional map's
        start (where it has pairs of its own), in this order, side by side in up to
        ``workers`` processes; a list of what :func:`screened` returns.  While the job
        ``pairs`` still runs, the workers take the starts ``own`` but the first, and this
        process screens the first and then the functional map's start: no core waits for the
        pairs while there is a start to screen."""
        functional = not own or self.l1.size < PAIR_BUDGET  # else its start has no pairs
        count = len(own) + functional
        screen = min(SCREEN_ITERATIONS, iterations)
        if count > 1 and self.workers > 1:
            self.say(f"screening {count} starts side by side (start 1 reports here)")
        fitted = self.l1.size >= 3  # own is the Möbius fit to the given landmarks alone
        jobs = [(screened, self, start, screen, f" (start {i + 1} of {count})", fitted)
                for i, start in enumerate(own)]
        last = f" (start {count} of {count})"
        if not functional:
            screens = side_by_side(jobs, self.workers)
            self.functional_pairs(pairs)  # its fine tips' pairs, for bend_tips
        elif pairs is None or self.spectral_pairs is not None or pairs.done() or not own:
            jobs.append((screened, self, self.spectral_start(pairs, timings), screen, last, True))
            screens = side_by_side(jobs, self.workers)
        else:
            def first():  # runs in this process (side_by_side's first job)
                head = screened(*jobs[0][1:])
                return head, screened(self, self.spectral_start(pairs, timings), screen, last,
                                      True)
            (head, tail), *rest = side_by_side([(first,)] + jobs[1:], self.workers)
            screens = [head, *rest, tail]
        for _, spent, _, _ in screens:
            add_timings(timings, spent)
        return screens

    def without_worst_pair(self, screen, iterations, timings):
        """The screening of the functional map's start (what :func:`screened` returns), or of
        the same start without its found pair of most distortion about it
        (:meth:`worst_pair`), whichever scores less.

        A functional map pairs a vertex now and then with a partner a limb's width off, too
        near on the sphere for the trimmed fit to drop (:func:`~.alignment.trimmed_fit`);
        placed as a landmark, it stretches the surface about it, and the start loses the
        screening however right its other pairs are.  Screening the start once more without
        the pair that stretches its surroundings most lets the score decide (a leave-one-out
        step, no threshold).  Only where the screening placed every pair: one left to its
        spring stretches nothing."""
        cand, spent, score, _ = screen
        p1, p2 = cand["start"].pairs
        k = self.l1.size
        if p1.size < 4 or cand["lm1"].size <= k or not cand["placed"].all():
            return screen
        keep = p1 != self.worst_pair(cand)
        F1 = self.problem1.F
        fit = landmark_start(F1, self.U1, np.concatenate([self.l1, p1[keep]]),
                             self.U2[np.concatenate([self.l2, p2[keep]])])
        start = Start(U=fit.U, label=cand["start"].label + "; its pair of most distortion "
                      "about it left out: " + fit.label, pairs=(p1[keep], p2[keep]))
        again = screened(self, start, min(SCREEN_ITERATIONS, iterations), " (again)", True)
        add_timings(timings, again[1])
        return again if again[2] < score else screen

    def worst_pair(self, cand):
        """The found pair's vertex of surface 1 (int) about which ``cand``'s screened map
        is most distorted: the area-weighted mean of ``|J - R|^2`` over the faces within
        :data:`PAIR_DISK` of it."""
        prob = self.problem(cand, descriptors=0.0)
        d = prob.distortions(cand["U"], cand["face"])[2]
        F1 = self.problem1.F
        dist = geodesics(self.V1s, F1)
        found = cand["lm1"][self.l1.size:]
        mean = [np.average(d, weights=prob.area * (dist(int(a))[F1].mean(axis=1) < PAIR_DISK))
                for a in found]
        return int(found[int(np.argmax(mean))])

    def resume(self, iterations, timings):
        """Finish the start :meth:`run` deferred (:meth:`complete`); what :meth:`run` returns."""
        best, notes = self.deferred
        self.deferred = None
        self.complete(best, iterations, timings)
        return self.outcome(best, notes)

    def outcome(self, best, notes):
        """``(U, stages, notes)`` of the finished start ``best``; sets :attr:`placed`."""
        self.placed = best["placed"][:self.l1.size].copy()
        return best["U"], self.stages(best), notes + self.notes(best)

    def finish(self, best, iterations, timings, defer=False):
        """The rest for a screened start ``best`` (in place): its whole bend where the
        screening's left landmarks unplaced (the given landmarks' whole bend is not repeated:
        :meth:`placed_on_targets`), :meth:`bend_tips`, then :meth:`complete`.  With ``defer``, a
        whole bend that left a given landmark unplaced ends it there (:meth:`run`).  Returns
        whether ``best`` was finished (bool).
        """
        bent = not best["placed"].all()
        if bent:
            self.bend(best, timings)
            if defer and not best["placed"][:self.l1.size].all():
                return False
        bent = self.bend_tips(best, timings) or bent
        self.complete(best, iterations, timings, fresh=bent or bool(self.coarse_levels))
        return True

    def bend_tips(self, best, timings):
        """``best``'s bent map bent on to the crowded fine-tip pairs (in place; their count in
        ``best["tips"]``): :func:`igl_spheremap.uses.fine_tips.crowded_tip_pairs`, then
        :func:`~igl_spheremap.uses.fine_tips.placed_tips`.  Whether any was placed (bool)."""
        t = time.perf_counter()
        a, b = crowded_tip_pairs(self.spectral_pairs, self.V1s, self.problem1.F, best["bent"],
                                 best["face"], self.phi, best["lm1"], best["lm2"])
        if a.size:
            self.say(f"bending surface 1's map to the {plural(a.size, 'crowded fine tip')}")
        U, lm1, lm2, placed = placed_tips(self.V1s, self.problem1.F, best["bent"], best["lm1"],
                                          best["lm2"], best["placed"], a, b, self.U2)
        best["tips"] = lm1.size - best["lm1"].size
        if best["tips"]:
            best.update(bent=U, lm1=lm1, lm2=lm2, placed=placed,
                        order=spread_order(self.V1s[lm1]))
        timings["landmarks"] += time.perf_counter() - t
        return best["tips"] > 0

    def complete(self, best, iterations, timings, fresh=True):
        """After the bend (in place): coarse levels and distortion stage from the bent map
        (``fresh``; else the screening's stage continued), landmarks near their targets placed
        and the stage repeated (``mode="hard"``, where a given one is unplaced: :meth:`snap`),
        the stage once more with less of the descriptor term or none (:meth:`last_stage`); the
        last with the robust penalty of :attr:`robust_scale` (or ``"auto"``'s)."""
        last = self.descriptor(best["placed"][:self.l1.size]) is None
        best["robust"] = self.robust_scale if last and self.robust_scale != "auto" else None
        if fresh:
            self.refine_from_bent(best, iterations, timings)
        elif iterations > SCREEN_ITERATIONS:
            self.refine_more(best, iterations - SCREEN_ITERATIONS, timings)
        if self.mode == "hard" and not best["placed"][:self.l1.size].all():
            self.snap(best, iterations, timings)
        if iterations and self.descriptor(best["placed"][:self.l1.size]) is not None:
            self.last_stage(best, iterations, timings)
        elif iterations and self.robust_scale == "auto":
            self.last_stage(best, iterations, timings, has_term=False)

    def released(self, cand, iterations):
        """``cand`` after ``iterations`` more steps of the distortion stage with only the given
        landmarks held (a new dict with its ``U``, ``face`` and ``history``; ``cand`` is left as
        it is).

        The pairs a start's own alignment found are placed as landmarks; right ones too hold
        its map off the distortion minimum, since the true map is not that minimum (the bent
        fish of the tests, the cats).  Scored where they hold it, a start with more pairs
        would lose to one with fewer however right its pairs are; released, the score says how
        low the basin the start leads to goes, and a wrong pair, which holds a start in a
        worse basin, still costs it (docs/decisions.md)."""
        k = self.l1.size
        free = dict(cand, lm1=cand["lm1"][:k], lm2=cand["lm2"][:k], placed=cand["placed"][:k])
        U, face, hist = refine(self.problem(free), cand["U"], cand["face"], iters=iterations)
        return dict(free, U=U, face=face, history=hist)

    def given_score(self, cand):
        """The distortion both ways of ``cand``'s map with the springs of the given landmarks
        only (float): the distortion stage's ARAP energy without the springs of the pairs the
        start's alignment found and without the descriptor term, plus
        :meth:`inverse_distortion`."""
        return self.given_distortion(cand) + self.inverse_distortion(cand["U"])

    def given_distortion(self, cand):
        """The forward part of :meth:`given_score` (float)."""
        k = self.l1.size
        given = dict(lm1=cand["lm1"][:k], lm2=cand["lm2"][:k], placed=cand["placed"][:k])
        return self.problem(given, descriptors=0.0).evaluate(cand["U"], cand["face"])[0]

    def final_rank(self, cand):
        """``(-placed, score)`` of a finished start, least best: in ``mode="hard"`` the given
        landmarks placed exactly come first (they are constraints; in ``"soft"`` none is), then
        :meth:`given_score`."""
        placed = int(cand["placed"][:self.l1.size].sum()) if self.mode == "hard" else 0
        return -placed, self.given_score(cand)

    def candidate(self, start, iterations, timings, which, staged=False):
        """One start, screened: bent to its landmarks (the given pairs, then the pairs the
        start's alignment found, each vertex once) by the all-at-once deformation (``staged``:
        where that leaves one unplaced, by the staged bend, whole for the given landmarks and
        quick for the found pairs, :meth:`placed_on_targets`) and
        refined by ``iterations`` of the distortion stage without the coarse levels; a dict of
        the maps on the way."""
        p1, p2 = start.pairs
        new = ~np.isin(p1, self.l1) & ~np.isin(p2, self.l2)
        lm1 = np.concatenate([self.l1, p1[new]]).astype(np.int64)
        lm2 = np.concatenate([self.l2, p2[new]]).astype(np.int64)
        cand = dict(start=start, lm1=lm1, lm2=lm2, order=spread_order(self.V1s[lm1]))
        self.bend(cand, timings, which, stages=False)
        if staged and not cand["placed"].all():
            self.bend(cand, timings, which, quick=True)
        self.refine_from_bent(cand, iterations, timings, which, coarse=False)
        return cand

    def bend(self, cand, timings, which="", stages=True, quick=False):
        """``cand``'s start bent to its landmarks (:meth:`placed_on_targets`; in place)."""
        t = time.perf_counter()
        if cand["lm1"].size:
            self.say(f"bending surface 1's map to {plural(cand['lm1'].size, 'landmark')}{which}")
        U, placed = self.placed_on_targets(cand["start"].U, cand, stages, quick)
        cand.update(bent=U, placed=placed, placed_first=placed.copy())
        timings["landmarks"] += time.perf_counter() - t

    def refine_from_bent(self, cand, iterations, timings, which="", coarse=True):
        """From ``cand``'s bent map: the coarse levels (unless ``coarse`` is False), then
        ``iterations`` of the distortion stage (in place)."""
        t = time.perf_counter()
        cand["coarse"] = []
        U = cand["coarse_U"] = (self.coarse_levels_run(cand["bent"], cand, which) if coarse
                                else cand["bent"])
        timings["coarse"] = timings.get("coarse", 0.0) + time.perf_counter() - t
        t = time.perf_counter()
        U1, face, hist = self.refined(U, cand, iterations)
        timings["refine"] += time.perf_counter() - t
        cand.update(U=U1, face=face, history=hist)

    def coarse_levels_run(self, U, cand, which):
        """Surface 1's map ``U`` after the distortion stage on each coarse level (appended to
        ``cand["coarse"]``: the levels' vertex counts and energies)."""
        n1 = self.V1s.shape[0]
        for count in self.coarse_levels:
            if 2 * count > n1:
                continue
            S, Fc = coarse_level(self.V1s, U, cand["lm1"], count)
            if S is None:
                continue
            self.say(f"lowering the distortion on {S.size:,} vertices of surface 1{which}")
            U, hist = coarse_stage(self.problem(cand, (S, Fc)), self.problem1.F, U, S, Fc,
                                   ITERATIONS, self.workers)
            cand["coarse"].append((S.size, hist[0], hist[-1]))
        return U

    def refine_more(self, best, iterations, timings):
        """More iterations of the distortion stage on ``best`` (in place)."""
        t = time.perf_counter()
        U1, face, more = self.refined(best["U"], best, iterations, best["face"])
        best.update(U=U1, face=face, history=best["history"] + more[1:])
        timings["refine"] += time.perf_counter() - t

    def snap(self, best, iterations, timings):
        """Place the landmarks the springs brought near their targets; refine again (in place).
        Only where a given landmark is unplaced (:meth:`complete`): ``"hard"`` is the caller's
        landmarks; a found pair the stage left on its spring is a hypothesis the distortion
        pushed back on, and bending it on costs the most where it fails (a retry per pair, on
        the whole mesh)."""
        t = time.perf_counter()
        self.say("placing the landmarks the distortion stage brought near their targets")
        U, placed = self.placed_on_targets(best["U"], best)
        timings["landmarks"] += time.perf_counter() - t
        if placed.sum() > best["placed"].sum():
            best.update(U=U, placed=placed, face=self.phi.start(U))
            self.refine_more(best, iterations, timings)

    def last_stage(self, best, iterations, timings, has_term=True):
        """The distortion stage once more (in place; with ``has_term`` False, below 8 landmarks,
        only for ``"auto"``'s robust penalty): the descriptor term chose the basin, and the map
        returned minimizes the distortion with less of it or none.  Where the map is
        near-isometric (:func:`~igl_spheremap.uses.surface_arap.auto_robust_scale`'s test) the
        term is off: there the descriptors differ mostly by the two triangulations and would hold
        the map off the distortion's minimum.  Elsewhere (two species, poses that stretch) the
        landmarks' harmonic coordinates still say what the distortion alone does not, and the
        term keeps :data:`LAST_STAGE_DESCRIPTORS` of its weight.  ``"auto"``'s penalty is taken
        where the map is near-isometric and dropped again where its map is not piecewise rigid
        (:func:`~igl_spheremap.uses.surface_arap.piecewise_rigid`)."""
        t = time.perf_counter()
        plain = self.problem(best, descriptors=0.0)
        near, median = auto_robust_scale(plain, best["U"], best["face"])
        kept = LAST_STAGE_DESCRIPTORS if has_term and near is None else 0.0
        words = descriptor_words(kept) if has_term else ""
        robust, note = self.robust_scale, ""
        if robust == "auto":
            robust = near
            if robust is None and not words:
                return
            note = "" if robust is None else f" (near-isometric: median stretch {median:.3f}"
        U1, face, alone = self.refined(best["U"], best, iterations, best["face"], kept, robust)
        if note:  # "auto" took the penalty: its map is kept where it came out piecewise rigid
            rigid, ratio = piecewise_rigid(plain, U1, face)
            verdict = "its map" if rigid else "the robust penalty's map not"
            note += (f"; {verdict} piecewise rigid: 90th / 50th percentile stretch {ratio:.2f}"
                     + ("" if rigid else ", plain ARAP") + ")")
            if not (rigid or words):  # below 8 landmarks the plain stage's map stays
                best["robust_note"] = note
                timings["refine"] += time.perf_counter() - t
                return
            if not rigid:
                U1, face, alone = self.refined(best["U"], best, iterations, best["face"], kept)
        best.update(with_descriptors=best["U"], U=U1, face=face, alone=alone, last_words=words)
        best["robust_note"] += note
        timings["refine"] += time.perf_counter() - t

    def stages(self, best):
        """Surface 1's map after each stage, for viewers."""
        start = best["start"]
        out = [dict(name="conformal map of surface 1, aligned", U=start.U, note=start.label)]
        if best["lm1"].size:
            out.append(dict(name="landmarks moved onto their targets" if self.l1.size else
                            "found landmark pairs moved onto their targets", U=best["bent"],
                            note=self.bend_note(best["placed_first"])))
        if best.get("coarse"):
            note = ", ".join(f"{c:,} vertices: {a:.4g} -> {b:.4g}" for c, a, b in best["coarse"])
            out.append(dict(name="distortion lowered on coarse levels of surface 1",
                            U=best["coarse_U"], note=note))
        steps = plural(len(best["history"]) - 1, "as-rigid-as-possible step")
        if "alone" in best:
            words = best["last_words"]
            out.append(dict(name="distortion between the surfaces lowered"
                                 + (", with descriptors" if words else ""),
                            U=best["with_descriptors"], note=steps))
            out.append(dict(name="distortion between the surfaces lowered"
                                 + ("" if words else ", robust penalty"), U=best["U"],
                            note=plural(len(best["alone"]) - 1, "as-rigid-as-possible step")
                                 + words + best["robust_note"]))
            return out
        out.append(dict(name="distortion between the surfaces lowered", U=best["U"],
                        note=steps + best["robust_note"]))
        return out

    def bend_note(self, placed):
        """The bend's flags in words: given landmarks first, then found pairs (and fine tips)."""
        parts = [f"{int(f.sum())} of {f.size} {what}" for f, what in zip(
            np.split(placed, [self.l1.size]), ("given landmarks", "found pairs")) if f.size]
        return " and ".join(parts) + " placed exactly"

    def refined(self, U, cand, iterations, face=None, descriptors=1.0, robust=None):
        """``(U, face, history)`` after ``iterations`` of :func:`refine` for the landmarks of
        ``cand`` (:meth:`problem`'s ``descriptors`` and ``robust``, this by default ``cand``'s)."""
        robust = cand.get("robust") if robust is None else robust
        cand["robust_note"] = "" if robust is None else f", robust penalty {robust:g}"
        prob = self.problem(cand, descriptors=descriptors, robust=robust)
        if iterations:
            has_term = self.descriptor(cand["placed"][:self.l1.size]) is not None
            term = descriptor_words(descriptors) if has_term else ""
            self.say(f"lowering the distortion between the surfaces ({plural(iterations, 'step')} "
                     f"at most{term}{'' if robust is None else ', robust penalty'})")
        face = self.phi.start(U) if face is None else face
        return refine(prob, U, face, iters=iterations)

    def notes(self, best):
        """Lines of the result's message on the start, the landmarks and the distortion stage."""
        out = [f"start kept: {best['start'].label}"]
        placed, hist, k = best["placed"], best["history"], self.l1.size
        if k:
            out.append(f"{int(placed[:k].sum())} of {k} landmarks placed exactly on the sphere"
                       + ("" if placed[:k].all() else
                          " (the others would fold faces; pulled by springs)"))
        if placed.size > k:
            tips = f" ({best['tips']} at fine tips)" if best.get("tips") else ""
            out.append(f"{int(placed[k:].sum())} of {placed.size - k} pairs found by the alignment"
                       f"{tips} placed as landmarks")
        for c, a, b in best.get("coarse", []):
            out.append(f"distortion stage on {c:,} vertices of surface 1: energy {a:.4g} -> "
                       f"{b:.4g}")
        robust = "" if "alone" in best else best["robust_note"]
        out.append(f"distortion stage{robust}: {plural(len(hist) - 1, 'step')}, energy "
                   f"{hist[0]:.4g} -> {hist[-1]:.4g}")
        if "alone" in best:
            a = best["alone"]
            out.append(f"then once more{best['last_words']}{best['robust_note']}: "
                       f"{plural(len(a) - 1, 'step')}, energy {a[0]:.4g} -> {a[-1]:.4g}")
        return out

    def final_map1(self, U1, folds, message):
        """Surface 1's final map as a :class:`SphericalMapResult` (rounds of its conformal map)."""
        return build_result(self.problem1, self.map1.rounds, U1, folds, message=message)


def screened(corr, start, iterations, which, staged=False):
    """One start of ``corr`` (a :class:`Correspondence`) screened (:meth:`Correspondence.candidate`)
    and scored by the distortion both ways of where its map goes with the pairs its own
    alignment found released (:meth:`Correspondence.released`): ``(cand, timings, score,
    given_score)``, the two scores the same (the score without the springs of the start's
    own pairs that :meth:`Correspondence.run` compares is this one), with the seconds it spent
    per stage (a :func:`igl_spheremap.uses.side_by_side.side_by_side` job; the starts are
    independent).

    The BLAS libraries are limited as in the calling process (a forked worker would
    otherwise start with their default threads, and sum in another order).  The
    descriptor terms a worker builds stay there: unpickled, their arrays lose the strides
    they were built with, and products over them round differently; the calling process
    builds its own (:meth:`Correspondence.descriptor`).  ``staged``: bent by the staged bend
    (:meth:`Correspondence.candidate`)."""
    timings = {"landmarks": 0.0, "refine": 0.0}
    with corr.problem1.options.blas_limit():
        cand = corr.candidate(start, iterations, timings, which, staged)
        t = time.perf_counter()
        free = corr.released(cand, iterations)
        timings["refine"] += time.perf_counter() - t
        score = free["history"][-1] + corr.inverse_distortion(free["U"])
        return cand, timings, score, score


def finished(corr, cand, iterations):
    """A screened start of ``corr`` finished (:meth:`Correspondence.finish`): ``(cand,
    timings)`` (a :func:`igl_spheremap.uses.side_by_side.side_by_side` job, BLAS limited as
    in :func:`screened`)."""
    timings = {"landmarks": 0.0, "refine": 0.0}
    with corr.problem1.options.blas_limit():
        corr.finish(cand, iterations, timings)
    return cand, timings


def add_timings(timings, spent):
    """Add the seconds per stage ``spent`` (dict of str to float) to ``timings`` (in place)."""
    for key, seconds in spent.items():
        timings[key] = timings.get(key, 0.0) + seconds


def _quiet(text):
    """A progress callback that reports nothing."""

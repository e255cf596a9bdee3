"""Algorithm 2 of the paper: folding removal by rounds of Algorithm 1 from new initial maps,
and the guaranteed path for meshes where the rounds cannot be trusted.

Modules: :mod:`.starts` (the Gauss map, Definition 1, and the central projection
from the mesh's kernel), :mod:`.star_map` (the weighted Laplace-Beltrami
eigen-projection, Section 4.2), :mod:`.problem` (a mesh with its operators and
options), :mod:`.rounds` (the round strategies and the loop), :mod:`.untangle` and
:mod:`.local_repair` (local removal of isolated folds, not in the paper),
:mod:`.centering` (the final Möbius centering), :mod:`.tutte_start` and
:mod:`.guaranteed` (starts fold-free by construction, not in the paper) and
:mod:`.result`.

What runs when
--------------
``method="paper"`` is the left-most path only: no fold barrier, no untangling,
no local repair, no round guard, no centering, no guaranteed path, float64.
Every other branch is part of ``method="folding_free"`` (the options that switch
it are named)::

    spherical_conformal_map(V, F)
    |
    +- validate_mesh; Laplacian (options.laplacian_kind), vertex areas
    |
    +- round 0, gauss_round: U0 = Gauss map
    |    +- U0 fold-free and fold_barrier ......... Algorithm 1 under the plain fold barrier
    |    +- else .................................. Algorithm 1 free
    |
    +- while the map folds and fewer than max_rounds rounds ran:
    |    +- round_guard, the round collapsed to degree 0, no restart yet, and a Tutte
    |    |     weighting fold-free ................ restart_round: Algorithm 1 free from
    |    |                                          the punctured Tutte map (degree 1)
    |    +- round_guard and a futile round: degree 0, or no fewer folds than before
    |    |     (a restart itself is not judged) ... stop: the best round that did not collapse
    |    +- after round 0 or a restart, local_repair, folds isolated (untangled, region
    |    |     <= 10% of the vertices)
    |    |     .................................... local_round: Algorithm 1 on the region
    |    |                                          under the fold barrier, the rest fixed
    |    +- else .................................. star_round: star map; its folds untangled
    |                                               (untangle; what is left, untangled
    |                                               patches: patched); Algorithm 1, under
    |                                               the fold barrier iff the start is fold-free
    |
    +- mobius: final_centering: Möbius-centered; if that folds a sliver, kernel moves
    |          (untangle or local_repair); kept iff no more folds (nor faces below the margin)
    |
    +- precision="float32", fold-free, faces below their margin: make_representable,
    |    repairs in turn until none is below (order by cause):
    |    +- round 0 under the barrier from a fold-free Gauss map:
    |    |                                          compressed metric, cluster inflation, central
    |    +- the central projection is fold-free:    central, cluster inflation, compressed metric
    |    +- else:                                   cluster inflation, compressed metric, central
    |
    +- guaranteed_path, and the verdict rejects the map (folds, degree not 1, faces below
    |    the margin, the barrier held more than half the vertices) or the map's E/4pi is
    |    below 1/2 (possibly collapsed in all but its degree; it then competes as a
    |    converged map); each start then runs the conformal descent (a barrier energy,
    |    steps capped per face, nothing frozen):
    |    +- central projection from the kernel centre (star-shaped meshes)
    |    +- punctured Tutte map lifted to the sphere (first weights fold-free and
    |    |     above the margin; where rounding broke them all, the disk untangled
    |    |     in the plane: untangled_disk, built only if the descent from the rounds'
    |    |     map fails where that map can start one; where every start failed, last,
    |    |     the first fold-free weights passed over for faces below the margin)
    |    +- the rounds' map when fold-free, degree 1 and, input slivers below the margin
    |    |     lifted, above it (polish); the initial map of its round instead, lifted the
    |    |     same way, where the barrier held over a tenth of the vertices there
    |    |     (held_start)
    |    +- keep the valid map (fold-free, degree 1, above the margin, once input
    |       slivers below it are lifted) of least angle distortion, the rounds' map
    |       among them; of the descents only those that converged, if any did (a
    |       stalled descent is no minimizer)
    |
    +- guaranteed_path, the verdict accepts the map, and the barrier froze more than a
    |    tenth of its vertices, has more than a tenth of its area on faces distorted
    |    over twice a conformal map's, or its round was patched (polish="auto"; every
    |    accepted map with "always", none with "never"): the conformal descent from
    |    it, the "polish" round (from its round's initial map where the barrier froze
    |    over a tenth of the vertices: held_start); its map kept iff it converged with
    |    a lower angle distortion
    |
    +- result: success = fold-free, converged, no face below its margin, not held by the
               barrier; the message notes a futile round, the path taken, a barrier
               that held more than half the vertices, faces left below the margin

``tests/test_decision_tree.py`` walks these branches on small constructed meshes
and checks that this drawing and ``docs/decision_tree.md`` agree.
"""

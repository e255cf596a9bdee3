"""Local untangling of the few folded faces a star map can keep (not in the paper)."""

from typing import NamedTuple

import numpy as np
import scipy.sparse as sp
import scipy.sparse.csgraph as csgraph

from ..mesh.arrays import as_faces, as_points
from ..mesh.topology import fill_holes, grow_region, vertex_adjacency, vertex_face_incidence
from ..sphere.chart import GnomonicChart, disk_patch, planar_signed_areas, tutte_embedding
from ..sphere.folds import fold_mask
from .untangled_disk import untangle_disk

#: Values of ``eps`` a patch's untangling may take (:func:`_untangled_patch`): the patches it
#: untangles on CAD parts take 2-26, one that fails would take all of ``MAX_STAGES``.
PATCH_STAGES = 30

#: Most vertices of a patch the untangling is tried on (:func:`_untangled_patch`): it is for
#: isolated folds; larger patches cost seconds and, on the corpus, untangled nothing that
#: changed a map (``docs/decisions.md``).
PATCH_VERTICES = 300


class _KernelProgram(NamedTuple):
    """Vertex ``v``'s program of :func:`_kernel_program`: maximize ``t`` subject to
    ``G @ (x, y, t) <= h``; the point is ``(x, y) * scale`` in ``chart``; ``current`` is the
    smallest signed distance of ``v``'s present position (chart origin), over ``scale``."""

    chart: GnomonicChart
    scale: float
    G: np.ndarray
    h: np.ndarray
    current: float


def _kernel_program(F, U, v, star):
    """The linear program of vertex ``v``'s move for its star ``star`` (face indices), or None.

    In the gnomonic chart at ``U[v]`` the star's faces ``(v, a, b)`` are
    positively oriented exactly when ``v`` lies left of every link edge
    ``a -> b``, i.e. in the kernel of the link polygon.  The program maximizes
    ``t`` subject to "signed distance of ``v`` to every link edge line >= t"
    (the Chebyshev center of the kernel), in chart coordinates divided by the
    link's extent ``s`` so that every vertex's program has unit size.

    Returns
    -------
    None, or a :class:`_KernelProgram` (``G`` (r, 3) and ``h`` (r,) float64, one
    row per link edge, the scale ``s``).
    """
    T = F[star]
    first = np.argmax(T == v, axis=1)
    rows = np.arange(T.shape[0])
    a, b = T[rows, (first + 1) % 3], T[rows, (first + 2) % 3]
    chart = GnomonicChart(U[v])
    P = U[np.concatenate([a, b])]
    if not chart.fits(P):
        return None
    X = chart.to_plane(P)
    s = np.abs(X).max()
    if not s > 0.0:
        return None
    X = X / s
    A, B = X[: a.size], X[a.size:]
    d = B - A
    length = np.linalg.norm(d, axis=1)
    if length.min() <= 0.0:
        return None
    h = d[:, 1] * A[:, 0] - d[:, 0] * A[:, 1]
    return _KernelProgram(chart, s, np.column_stack([d[:, 1], -d[:, 0], length]), h,
                          np.min(h / length))


def _kernel_moves(F, U, VF, verts):
    """Best positions of the vertices ``verts`` for their stars: ``{v: unit position}``.

    Each vertex goes to the Chebyshev center of its link's kernel
    (:func:`_kernel_program`) when that raises the smallest signed distance of
    its star above its current value (``t > 0``: the star is unfolded); the
    others are left out.  No two of ``verts`` may be adjacent: then no
    vertex's program depends on another's move, and the programs are solved as
    one (block-diagonal, separable: its optimum is each block's optimum), one
    call to the solver instead of one per vertex; if the solver fails on the
    joint program (a numerical failure: every block is feasible and bounded),
    each vertex's program is solved alone.
    """
    blocks = []
    for v in verts:
        prog = _kernel_program(F, U, v, VF.indices[VF.indptr[v]:VF.indptr[v + 1]])
        if prog is not None:
            blocks.append((v, prog))
    if not blocks:
        return {}
    progs = [prog for _, prog in blocks]
    solved = _chebyshev_centres(progs)
    if solved is None and len(progs) > 1:
        solved = [_chebyshev_centres([prog]) for prog in progs]
        solved = [None if row is None else row[0] for row in solved]
    if solved is None:
        return {}
    moves = {}
    for (v, prog), row in zip(blocks, solved):
        if row is None:
            continue
        x, y, t = row
        if t > prog.current:
            chart = prog.chart
            p = chart.c + prog.scale * (x * chart.e1 + y * chart.e2)
            moves[v] = p / np.linalg.norm(p)
    return moves


def _chebyshev_centres(progs):
    """``(x, y, t)`` of each of the programs ``progs`` (list of :class:`_KernelProgram`) as a
    (len(progs), 3) float64 array, solved as one block-diagonal linear program by HiGHS; None
    if the solver fails."""
    from scipy.optimize import linprog  # scipy.optimize only when a fold needs a kernel move

    G = sp.block_diag([prog.G for prog in progs], format="csr")
    h = np.concatenate([prog.h for prog in progs])
    bounds = [(-2.0, 2.0), (-2.0, 2.0), (None, 2.0)] * len(progs)
    c = np.tile([0.0, 0.0, -1.0], len(progs))
    res = linprog(c, A_ub=G, b_ub=h, bounds=bounds, method="highs")
    return res.x.reshape(-1, 3) if res.status == 0 else None


def _sweep_groups(A, verts):
    """``verts`` (ascending) in groups to be moved in turn as if one at a time in ascending order.

    A vertex's group comes after the groups of its neighbors in ``verts`` that
    precede it, and no two vertices of a group are adjacent in ``A``: moving
    the groups in turn, each group at once, gives exactly the Gauss-Seidel sweep
    over ``verts`` in ascending order (a level schedule; each move depends
    only on the vertex's neighbors).

    Parameters
    ----------
    A : (n, n) scipy.sparse.csr_matrix
        Vertex adjacency.
    verts : (k,) int64 array
        Ascending vertex indices.

    Returns
    -------
    list of (k_i,) int64 arrays
        The groups, in order; their union is ``verts``.
    """
    lower = sp.tril(A[verts][:, verts], k=-1, format="csr")
    level = np.zeros(verts.size, dtype=np.int64)
    for i in range(verts.size):
        before = lower.indices[lower.indptr[i]:lower.indptr[i + 1]]
        if before.size:
            level[i] = level[before].max() + 1
    return [verts[level == j] for j in range(int(level.max()) + 1)] if verts.size else []


def _kernel_sweeps(F, U, VF, A, max_sweeps, fixed):
    """Move vertices of folded faces to the kernels of their links, as if one at a time.

    Gauss-Seidel sweeps of :func:`_kernel_moves` over the vertices of folded
    faces (and, after a sweep that removed no fold, also their neighbors),
    except the ``fixed`` ones, in the groups of :func:`_sweep_groups`; stops when
    the widened sweep removes none either.  Modifies ``U`` in place, leaving the
    state with the fewest folded faces seen: a kernel move raises the smallest
    signed distance of its star, but while that stays negative it can fold
    faces of the star that were not folded, so a sweep can end with more folds
    than it started with.  Returns the number of folded faces left.
    """
    stuck = 0
    best, best_U = None, None
    for _ in range(max_sweeps):
        folded = fold_mask(F, U)
        count = int(np.count_nonzero(folded))
        if count == 0:
            return 0
        if best is not None and count >= best:
            stuck += 1
            if stuck == 2:  # not even the widened sweep removed a fold
                break
        else:
            stuck = 0
            best, best_U = count, U.copy()
        cand = np.zeros(U.shape[0], dtype=bool)
        cand[F[folded].ravel()] = True
        if stuck:
            cand = grow_region(A, cand)
        cand &= ~fixed
        for group in _sweep_groups(A, np.flatnonzero(cand)):
            for v, p in _kernel_moves(F, U, VF, group).items():
                U[v] = p
    count = int(np.count_nonzero(fold_mask(F, U)))
    if best is not None and count > best:
        U[:] = best_U
        count = best
    return count


def _patch_chart(F, U, inside, faces):
    """``(verts, Fl, fixed, chart, X)``: the patch as a disk (:func:`disk_patch`) whose
    interior is exactly ``inside``, in the gnomonic chart around it, ``X`` ((k, 2)) its
    boundary's chart positions (zero inside); None when it is no such disk or its boundary
    does not fit in one chart."""
    patch = disk_patch(F, faces, inside)
    if patch is None:
        return None
    verts, Fl, fixed = patch
    if np.count_nonzero(~fixed) != np.count_nonzero(inside):
        return None
    P = U[verts]
    chart = GnomonicChart.around(P)
    if not chart.fits(P[fixed]):
        return None
    X = np.zeros((verts.size, 2))
    X[fixed] = chart.to_plane(P[fixed])
    return verts, Fl, fixed, chart, X


def _tutte_patch(F, U, inside, faces):
    """Re-embed the vertices ``inside`` by a Tutte embedding in a gnomonic chart.

    Returns the new positions of the ``inside`` vertices, or None when the
    patch is not a disk whose interior is exactly ``inside``, or does not fit
    in one chart.  The embedding is fold-free when the boundary polygon is
    convex (Tutte's theorem); the caller checks the result, since the boundary
    is not always convex.  (The interior is re-embedded, so where its vertices
    are now does not matter: a vertex flung to the far side of the sphere is
    brought back.)
    """
    patch = _patch_chart(F, U, inside, faces)
    if patch is None:
        return None
    verts, Fl, fixed, chart, X = patch
    Y = tutte_embedding(X, Fl, fixed)
    return verts[~fixed], chart.to_sphere(Y[~fixed])


def _untangled_patch(F, U, inside, faces):
    """:func:`_tutte_patch`, its embedding then untangled in the chart by Garanzha et al.'s
    method (:func:`igl_spheremap.folding.untangled_disk.untangle_disk`, at most
    :data:`PATCH_STAGES` values of ``eps``) toward equilateral triangles, the boundary
    fixed; None also for a patch of more than :data:`PATCH_VERTICES` vertices.  Tutte's
    theorem needs a convex boundary; the untangling does not."""
    patch = _patch_chart(F, U, inside, faces) if faces.size <= 2 * PATCH_VERTICES else None
    if patch is None or patch[0].size > PATCH_VERTICES:
        return None
    verts, Fl, fixed, chart, X = patch
    X = tutte_embedding(X, Fl, fixed)
    if planar_signed_areas(X, Fl).sum() < 0:  # the chart's orientation
        Fl = Fl[:, ::-1]
    X, _ = untangle_disk(None, Fl, X, fixed, max_stages=PATCH_STAGES)
    return verts[~fixed], chart.to_sphere(X[~fixed])


def untangle_folds(F, U, max_rings=12, max_sweeps=20, max_passes=3, max_kernel_folds=1000, *,
                   adjacency=None, fixed=None, within=None):
    """Remove isolated folded faces by local re-embedding.

    Passes of two local stages, Tutte patches then kernel sweeps, repeated
    while a pass removes folds.

    *Tutte patches*: around each cluster of folded faces, the ``k``-ring
    patch (``k = 1, 2, ..., max_rings``) is mapped to the tangent plane by the
    gnomonic projection (central projection, which keeps the sign of every
    image triangle's orientation); if the patch is a disk that fits in one
    chart, its interior vertices are replaced by the uniform-weight Tutte
    embedding with its boundary fixed and projected back to the sphere.  By
    Tutte's theorem that is fold-free when the boundary polygon is convex; a
    patch is kept only if it is fold-free, so a non-convex boundary (which can
    fold) leaves it unchanged.

    *Kernel sweeps*: each vertex of a folded face left is moved, one vertex at
    a time, to the Chebyshev center of the kernel of its link polygon in a
    gnomonic chart (a small linear program, as in optimization-based
    untangling for mesh smoothing, posed at the link's scale so that a star
    crowded into micro-radians is solved as well as a large one), which
    unfolds its whole star whenever that kernel is not empty.  Vertices that
    are not adjacent do not affect each other's programs, so each sweep solves
    them in groups, one program per group, ordered so that the sweep is the
    one-vertex-at-a-time sweep (up to the solver's choice among equally good
    centers).  Sweeps repeat while they remove folds, widening to
    the neighbors of folded faces when a sweep gets stuck: they remove the
    folds Tutte patches leave at non-convex patch boundaries.

    Where they leave folds, :func:`untangle_patches` may remove them at some cost in angle.

    Faces away from the folds are unchanged, and so are the ``fixed`` vertices
    (hard landmarks): they stay on the boundary of a Tutte patch (a patch
    whose interior would contain one is skipped) and the kernel sweeps pass
    them over.
    The result is not conformal inside the patches; Algorithm 1 with the fold
    barrier polishes it afterwards.

    Parameters
    ----------
    F : (m, 3) int64 array
    U : (n, 3) float64 array
        Map with a few folded faces (unit rows).
    max_rings : int
        Largest patch radius, in edge rings around the folded faces.
    max_sweeps : int
        Cap on kernel sweeps per pass.
    max_passes : int
        Cap on passes.
    max_kernel_folds : int
        Kernel sweeps run only when at most this many folded faces are left
        after the Tutte patches (they are for isolated folds; each vertex adds
        three variables to its group's linear program).
    adjacency : (n, n) scipy.sparse.csr_matrix, optional
        The vertex adjacency of ``F`` if the caller has it (1 for every edge); with
        ``within`` it finds the submesh, whose own adjacency is built.
    fixed : (n,) bool array, optional
        Vertices that must not move (True = keep ``U``'s row bit for bit);
        default none.  Folds that only moving them would remove are left.
    within : int, optional
        Untangle on the faces with a corner within this many edge rings of the folded
        faces only, their corners farther out fixed: the same patches and sweeps as on the
        whole mesh where they stay inside, at a cost that does not grow with the mesh (a
        few folds of a 50k-vertex map, as a landmark deformation's step leaves).  Default:
        the whole mesh.

    Returns
    -------
    U : (n, 3) float64 array
        Map with the untangled patches replaced (a copy).
    remaining : int
        Folded faces left.

    Raises
    ------
    ValueError
        ``U`` is not (n, 3) finite numbers, ``F`` not (m, 3) integer indices into it, or
        ``fixed`` not an (n,) mask.
    """
    as_points(U, "U")  # checked; the copy keeps U's memory layout (and so the map's bits)
    U = np.array(U, dtype=np.float64, copy=True)
    n = U.shape[0]
    F = as_faces(F, n)
    fixed = np.zeros(n, dtype=bool) if fixed is None else np.asarray(fixed, dtype=bool)
    if fixed.shape != (n,):
        raise ValueError(f"fixed must be a ({n},) bool mask, got shape {fixed.shape}")
    limits = max_rings, max_sweeps, max_passes, max_kernel_folds
    A = vertex_adjacency(F, n) if adjacency is None else adjacency
    if within is not None:
        return _untangle_within(F, U, A, fixed, within, limits)
    return U, _passes(F, U, A, fixed, None, limits)


def untangle_patches(F, U, max_rings=12, max_sweeps=20, max_kernel_folds=1000, *,
                     adjacency=None, fixed=None):
    """:func:`untangle_folds`, then, where it leaves folds, untangled patches.

    The Tutte patches of :func:`untangle_folds` once more, each Tutte embedding
    untangled in its gnomonic chart by the method of Garanzha, Kaporin, Kudryavtseva,
    Protais, Ray, Sokolov ("Foldover-free maps in 50 lines of code", ACM TOG 40(4),
    2021) toward equilateral triangles, the boundary fixed, which needs no convex
    boundary; then kernel sweeps once more if a patch was kept.  On CAD parts the
    harmonic map's folds sit among long fan triangles, where no Tutte patch up to
    ``max_rings`` rings has a boundary convex enough.  A kept patch is shaped toward
    equilateral triangles, not toward the map around it: far from conformal.

    Parameters
    ----------
    F : (m, 3) int64 array
    U : (n, 3) float64 array
        Unit rows.
    max_rings, max_sweeps, max_kernel_folds : int
        As in :func:`untangle_folds`; no patch is untangled above ``max_kernel_folds`` folds.
    adjacency : (n, n) sparse matrix, optional
        :func:`~igl_spheremap.mesh.topology.vertex_adjacency` of ``F``, if at hand.
    fixed : (n,) bool array, optional
        Vertices that do not move, as in :func:`untangle_folds`.

    Returns
    -------
    U : (n, 3) float64 array
        A copy, untangled.
    remaining : int
        Folded faces left.
    patched : bool
        Whether an untangled patch was kept.
    """
    A = vertex_adjacency(F, U.shape[0]) if adjacency is None else adjacency
    U, left = untangle_folds(F, U, max_rings, max_sweeps, max_kernel_folds=max_kernel_folds,
                             adjacency=A, fixed=fixed)
    if not 0 < left <= max_kernel_folds:
        return U, left, False
    fixed = np.zeros(U.shape[0], dtype=bool) if fixed is None else np.asarray(fixed, dtype=bool)
    VF = vertex_face_incidence(F, U.shape[0])
    if not _tutte_patches(F, U, VF, A, max_rings, fixed, None, _untangled_patch):
        return U, left, False
    left = int(np.count_nonzero(fold_mask(F, U)))
    if left:
        left = _kernel_sweeps(F, U, VF, A, max_sweeps, fixed)
    return U, left, True


def _passes(F, U, A, fixed, outside, limits):
    """The passes of :func:`untangle_folds` on ``U`` (in place); the folded faces left.
    ``outside``: the rim of a submesh (:func:`_untangle_within`), or None."""
    max_rings, max_sweeps, max_passes, max_kernel_folds = limits
    VF = vertex_face_incidence(F, U.shape[0])
    left = int(np.count_nonzero(fold_mask(F, U)))
    for _ in range(max_passes):
        if left == 0:
            break
        _tutte_patches(F, U, VF, A, max_rings, fixed, outside)
        before, left = left, int(np.count_nonzero(fold_mask(F, U)))
        if left > max_kernel_folds:
            break  # not isolated folds: a linear program per vertex would take minutes
        left = _kernel_sweeps(F, U, VF, A, max_sweeps, fixed)
        if left >= before:
            break
    return left


def _untangle_within(F, U, A, fixed, rings, limits):
    """:func:`untangle_folds` of ``U`` (a copy, changed in place) on the faces with a corner
    within ``rings`` edge rings of its folded faces, their other corners (the rim) fixed,
    so that every vertex that may move keeps its whole star; ``(U, folded faces left)``.
    The submesh keeps the order of the vertices (its sweeps run in the same order as on
    the whole mesh), and a patch's holes are what its ring encloses away from the rim."""
    near = np.zeros(U.shape[0], dtype=bool)
    near[F[fold_mask(F, U)].ravel()] = True
    if not near.any():
        return U, 0
    near = grow_region(A, near, rings)
    verts, Fs = np.unique(F[near[F].any(axis=1)], return_inverse=True)
    Fs, rim = Fs.reshape(-1, 3), ~near[verts]
    Us = U[verts]
    left = _passes(Fs, Us, vertex_adjacency(Fs, verts.size), fixed[verts] | rim, rim, limits)
    U[verts] = Us
    return U, left


def _tutte_patches(F, U, VF, A, max_rings, fixed, outside=None, embed=_tutte_patch):
    """Replace ``k``-ring patches around folded faces by Tutte embeddings (in place).

    The ``fixed`` vertices are taken out of each patch's interior; one that is
    then not on the patch's boundary loop makes :func:`_tutte_patch` refuse
    the patch (its interior vertices must be exactly the ones it may move).
    ``outside``: :func:`~igl_spheremap.mesh.topology.fill_holes`'s, on a submesh.
    ``embed``: the patch's new interior, :func:`_tutte_patch` or :func:`_untangled_patch`.
    Returns whether a patch was kept.
    """
    n, kept = U.shape[0], False
    for rings in range(1, max_rings + 1):
        folded = fold_mask(F, U)
        if not folded.any():
            return kept
        region = np.zeros(n, dtype=bool)
        region[F[folded].ravel()] = True
        region = fill_holes(A, grow_region(A, region, rings), outside) & ~fixed
        ncomp, labels = csgraph.connected_components(A[region][:, region], directed=False)
        idx = np.flatnonzero(region)
        for comp in range(ncomp):
            members = idx[labels == comp]
            inside = np.zeros(n, dtype=bool)
            inside[members] = True
            faces = np.unique(VF[members].indices)
            patch = embed(F, U, inside, faces)
            if patch is None:
                continue
            verts, Y = patch
            old = U[verts].copy()
            U[verts] = Y
            if fold_mask(F[faces], U).any():
                U[verts] = old
            else:
                kept = True
    return kept

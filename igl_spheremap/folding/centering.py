"""The final Möbius centering of Algorithm 2's map (not in the paper)."""

from ..sphere.folds import below_margin, count_folds
from ..sphere.mobius import mobius_center
from .untangle import untangle_folds


def final_centering(problem, U, folds):
    """``U`` (input order), Möbius-centered if that folds no more faces (kernel moves for slivers).

    Re-centering a fold-free map can flip a near-degenerate sliver (signed volume ~1e-17);
    its vertices then get the kernel moves of
    :func:`igl_spheremap.folding.untangle.untangle_folds` (with untangling or local repair on).
    A map that folds already (Algorithm 2 did not remove its folds) is centred only when that
    folds no more faces, without the kernel moves: on a map collapsed to degree 0 they sweep
    hundreds of folded faces for nothing, as the guaranteed path replaces it
    (``docs/decisions.md``).  With ``options.precision="float32"`` the centered map must
    also leave no more faces below their rounding margin.

    Returns
    -------
    U : (n, 3) float64 array
        In the validated mesh's order.
    folds : int
    """
    opts, F = problem.options, problem.F
    U = problem.mesh.from_input(U)
    if opts.mobius:
        centered, _ = mobius_center(U, problem.area)
        left = count_folds(F, centered)
        if folds == 0 and left > 0 and (opts.untangle or opts.local_repair):
            centered, left = untangle_folds(F, centered, max_rings=0)
        if left <= folds and (opts.precision == "float64" or
                              below_margin(F, centered, opts.precision).sum()
                              <= below_margin(F, U, opts.precision).sum()):
            U = centered
    return U, count_folds(F, U)

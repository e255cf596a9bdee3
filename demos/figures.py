#!/usr/bin/env python
"""Convergence and angle-distortion plots of a spherical conformal map run (paper Figs. 4, 10).

    python demos/figures.py --out out/figures                  # bundled dino
    python demos/figures.py my_mesh.obj --method paper --out out/figures
    python demos/figures.py --load-result out/dino.npz --out out/figures

Writes (matplotlib, Agg backend, no display needed):

``energy.png``
    harmonic energy / 4 pi against the iteration number, rounds concatenated
    (paper Fig. 4, top row); 1 is the energy of a conformal bijection.
``grad_norm.png``
    RMS Riemannian gradient (the stopping quantity) on a log axis.
``angle_histograms.png``
    histograms of the per-corner angle differences |angle on the sphere - angle
    on the input| in degrees, before folding removal (the map after the first
    Algorithm 1 run) and after (the final map) (paper Fig. 4 bottom, Fig. 10).

Exit codes: 0 done, 1 a file cannot be read or an option is wrong, 2 the mesh is
not a closed genus-0 manifold triangle mesh; one line on stderr, no traceback.
"""

import importlib.resources
import os
import sys

import numpy as np

import igl_spheremap
from igl_spheremap.cli.common import Parser, non_negative_int
from igl_spheremap.errors import MeshError
from igl_spheremap.folding.guaranteed import DESCENT_GTOL
from igl_spheremap.io import read_mesh
from igl_spheremap.io.result_file import load_result
from igl_spheremap.viz.stages import STARTS

DEFAULT_MESH = os.fspath(importlib.resources.files("igl_spheremap") / "data" / "dino.obj")


def _pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def is_descent(rnd):
    """Whether a round ran the conformal descent (the polish and the guaranteed path's starts).

    Such a round minimizes the conformal distortion, not the harmonic energy, and
    stops at :data:`igl_spheremap.folding.guaranteed.DESCENT_GTOL`, not at ``options.gtol``;
    the restart after a collapse runs Algorithm 1 as the star rounds do.
    """
    return rnd.kind in STARTS and rnd.kind != "restart"


def round_label(rnd):
    """Legend text of a round: its number and the map it started from (str)."""
    if rnd.kind in STARTS:
        title = STARTS[rnd.kind][0]
        return (f"round {rnd.index}: conformal descent from the {title}" if is_descent(rnd)
                else f"round {rnd.index} (from the {title})")
    start = {"gauss": "Gauss map", "local": "untangled map"}.get(rnd.kind, f"star map {rnd.index}")
    return f"round {rnd.index} (from {start})"


def round_gtol(result, rnd):
    """The RMS Riemannian gradient at which a round stops (float; see :func:`is_descent`)."""
    return DESCENT_GTOL if is_descent(rnd) else result.options.gtol


def _concatenated(result, attr, scale=1.0):
    """Per round: (iteration numbers, values), iterations counted across rounds."""
    out, start = [], 0
    for rnd in result.rounds:
        y = np.asarray(getattr(rnd, attr), dtype=np.float64) * scale
        x = start + np.arange(y.size)
        out.append((rnd, x, y))
        start += max(y.size - 1, 0)
    return out


def plot_energy(result, path):
    """Energy / 4 pi per Algorithm 1 iterate, one line per round.

    The harmonic energy, except in the conformal-descent rounds (:func:`is_descent`),
    whose lines are their conformal distortion, the energy they minimize (also
    ``4 pi`` for a conformal map); their legend says so.

    Parameters
    ----------
    result : SphericalMapResult
    path : str
        PNG to write.

    Returns
    -------
    str
        ``path``.
    """
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 4.2), dpi=120)
    for rnd, x, y in _concatenated(result, "energy_history", 1.0 / (4 * np.pi)):
        energy = " (conformal distortion)" if is_descent(rnd) else ""
        ax.plot(x, y, lw=1.6, label=f"{round_label(rnd)}{energy}: {rnd.folds_before} → "
                                    f"{rnd.folds_after} folded faces")
        ax.axvline(x[0], color="0.75", lw=0.8, ls=":")
    ax.axhline(1.0, color="k", lw=0.8, ls="--", label="4π (conformal bijection)")
    ax.set_xlabel("Algorithm 1 iteration (rounds concatenated)")
    descent = any(is_descent(rnd) for rnd in result.rounds)
    ax.set_ylabel("energy / 4π" if descent else "harmonic energy / 4π")
    ys = np.concatenate([y for _, _, y in _concatenated(result, "energy_history",
                                                          1.0 / (4 * np.pi))])
    if ys.size and np.nanmax(ys) > 20 * max(np.nanmin(ys), 1e-300):
        ax.set_yscale("log")
    ax.set_title(("Harmonic energy, conformal distortion in the descent" if descent else
                  "Harmonic energy") + f" ({result.options.method})")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


def plot_grad_norm(result, path):
    """RMS Riemannian gradient per Algorithm 1 iterate (log axis), one line per round.

    A dashed line per stopping threshold in use: ``options.gtol`` and, when the
    run has conformal-descent rounds, their own (:func:`round_gtol`).

    Parameters
    ----------
    result : SphericalMapResult
    path : str

    Returns
    -------
    str
        ``path``.
    """
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 4.2), dpi=120)
    for rnd, x, y in _concatenated(result, "grad_norm_history"):
        ax.semilogy(x, np.maximum(y, 1e-300), lw=1.2, label=round_label(rnd))
        ax.axvline(x[0], color="0.75", lw=0.8, ls=":")
    gtols = {}
    for rnd in result.rounds:
        what = "conformal descent" if is_descent(rnd) else "Algorithm 1"
        gtols.setdefault(round_gtol(result, rnd), []).append(what)
    for (gtol, whats), ls in zip(sorted(gtols.items()), ("--", "-.")):
        ax.axhline(gtol, color="k", lw=0.8, ls=ls,
                   label=f"gtol = {gtol:g} ({', '.join(dict.fromkeys(whats))})")
    ax.set_xlabel("Algorithm 1 iteration (rounds concatenated)")
    ax.set_ylabel("RMS Riemannian gradient")
    ax.set_title("Stopping quantity")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


def angle_differences(result):
    """Angle differences (degrees) before and after folding removal.

    Returns
    -------
    before, after : (3 m,) float64 arrays
        :func:`igl_spheremap.angle_distortion` of ``rounds[0].U`` (Gauss map +
        Algorithm 1) and of the final map ``result.U``, on the mesh the result
        carries; non-finite corners (collapsed image triangles) dropped.
    """
    mesh = result.mesh
    out = []
    for U in (result.rounds[0].U, result.U):
        with np.errstate(invalid="ignore", divide="ignore"):
            a = igl_spheremap.angle_distortion(mesh.V, mesh.F, mesh.from_input(U)).ravel()
        out.append(a[np.isfinite(a)])
    return out[0], out[1]


def after_title(result):
    """Title of the final map's histogram: the folding-removal rounds (star, local, restart)
    counted apart from the conformal descent (the polish, the guaranteed path's rounds)."""
    rounds = result.rounds[1:]
    nr = sum(not is_descent(rnd) for rnd in rounds)
    descent = [rnd.kind for rnd in rounds if is_descent(rnd)]
    title = f"after folding removal ({nr} round{'' if nr == 1 else 's'}"
    if descent:
        title += " + the polish" if descent == ["polish"] else " + the conformal descent"
    return title + ")"


def plot_angle_histograms(result, path):
    """Histograms of angle differences before vs after folding removal (paper Figs. 4, 10).

    Parameters
    ----------
    result : SphericalMapResult
    path : str

    Returns
    -------
    str
        ``path``.
    """
    plt = _pyplot()
    before, after = angle_differences(result)
    r0 = result.rounds[0]
    hi = max(float(np.percentile(np.concatenate([before, after]), 99.5)), 1.0)
    bins = np.linspace(0.0, hi, 61)
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8), dpi=120, sharex=True, sharey=True)
    for ax, a, title, folds, color in (
            (axes[0], before, "before folding removal (Gauss map + Algorithm 1)",
             r0.folds_after, "#c0392b"),
            (axes[1], after, after_title(result),
             result.folds, "#1f77b4")):
        ax.hist(np.minimum(a, hi), bins=bins, color=color, alpha=0.85)
        ax.set_title(f"{title}\n{folds} folded faces", fontsize=10)
        ax.set_xlabel(f"angle difference (degrees; last bin: ≥ {hi:.0f}°)")
        ax.text(0.97, 0.95, f"mean {a.mean():.2f}°\nmedian {np.median(a):.2f}°\n"
                            f"95% {np.percentile(a, 95):.2f}°",
                transform=ax.transAxes, ha="right", va="top", fontsize=9)
    axes[0].set_ylabel("corners")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


def write_figures(result, out_dir):
    """Write ``energy.png``, ``grad_norm.png`` and ``angle_histograms.png`` into ``out_dir``.

    Returns
    -------
    list of str
        The paths written.
    """
    os.makedirs(out_dir, exist_ok=True)
    return [plot_energy(result, os.path.join(out_dir, "energy.png")),
            plot_grad_norm(result, os.path.join(out_dir, "grad_norm.png")),
            plot_angle_histograms(result, os.path.join(out_dir, "angle_histograms.png"))]


def main(argv=None):
    ap = Parser(description=__doc__.split("\n\n")[0])
    ap.add_argument("mesh", nargs="?", default=None,
                    help="closed genus-0 triangle mesh (default: the bundled dino.obj)")
    ap.add_argument("--out", required=True, metavar="DIR", help="directory for the PNGs")
    ap.add_argument("--method", choices=("folding_free", "paper"), default="folding_free")
    ap.add_argument("--max-iter", type=non_negative_int, default=None,
                    help="cap on Algorithm 1 iterations per round (default: the method's)")
    ap.add_argument("--max-rounds", type=non_negative_int, default=6,
                    help="folding-removal rounds at most (default 6)")
    ap.add_argument("--load-result", metavar="FILE.npz",
                    help="use a result saved by folding_removal.py --save-result")
    args = ap.parse_args(argv)
    try:
        if args.load_result:
            result = load_result(args.load_result)
        else:
            V, F, _ = read_mesh(args.mesh or DEFAULT_MESH)
            result = igl_spheremap.spherical_conformal_map(
                V, F, method=args.method, max_rounds=args.max_rounds, max_iter=args.max_iter)
    except MeshError as err:          # as folding_removal.py: one line, no traceback
        print(f"error: {err}", file=sys.stderr)
        return 2
    except (OSError, ValueError) as err:
        print(f"error: {err}", file=sys.stderr)
        return 1
    print(result.message)
    for p in write_figures(result, args.out):
        print(p)
    return 0


if __name__ == "__main__":
    sys.exit(main())

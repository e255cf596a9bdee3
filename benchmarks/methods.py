"""The spherical-map methods the benchmarks time, and :func:`run_case`, one method on one mesh.

Each method of :data:`METHODS` is a function ``method(V, F, opts, clock) -> dict`` that
does its untimed set-up, runs the timed call inside ``with clock:`` and returns the
map ``U`` with its bookkeeping (rounds, iterations, converged, message, notes).
:func:`run_case` runs one of them on one mesh in a fresh child process
(:func:`harness.run_in_child`): the reported peak memory is that process's own, and a
crash or timeout of one method cannot take the others down.  Every method is timed
the same way (:func:`harness.timed_calls`).
"""

import sys
import traceback

import numpy as np

from harness import (REPEATS, Clock, load_mesh, mesh_name, one_line, peak_rss_mib, quality_row,
                     run_in_child, timed_calls)
from igl_spheremap.io.write_report import json_ready


def _map_options(opts):
    return {k: opts[k] for k in ("max_rounds", "gtol", "max_iter", "precision")
            if opts.get(k) is not None}


def _ours_default(V, F, opts, clock):
    """Our default pipeline: ``spherical_conformal_map(V, F)`` (method "folding_free")."""
    import igl_spheremap as sm
    kw = _map_options(opts)
    with clock:
        r = sm.spherical_conformal_map(V, F, **kw)
    return _from_spherical_result(r)


def _ours_polish(V, F, opts, clock):
    """The default pipeline with ``polish="always"`` (the conformal descent from every accepted map)."""
    import igl_spheremap as sm
    kw = _map_options(opts)
    with clock:
        r = sm.spherical_conformal_map(V, F, polish="always", **kw)
    return _from_spherical_result(r)


def _ours_default_superlu(V, F, opts, clock):
    """The default pipeline as installed without the ``cholmod`` extra (H1 metric by SuperLU)."""
    for name in ("sksparse", "sksparse_minimal"):  # as if not installed (this child only)
        sys.modules[name] = None
    return _ours_default(V, F, opts, clock)


def _ours_paper(V, F, opts, clock):
    """The paper's Algorithm 2 as published: ``spherical_conformal_map(V, F, method="paper")``."""
    import igl_spheremap as sm
    kw = _map_options(opts)
    with clock:
        r = sm.spherical_conformal_map(V, F, method="paper", **kw)
    return _from_spherical_result(r)


def _from_spherical_result(r):
    return dict(U=r.U, rounds=len(r.rounds) - 1, nit=r.nit, converged=bool(r.converged),
                message=r.message,
                extra=dict(round_kinds=[x.kind for x in r.rounds],
                           round_nit=[x.nit for x in r.rounds],
                           round_folds=[x.folds_after for x in r.rounds],
                           round_seconds=[x.seconds for x in r.rounds],
                           library_seconds=r.seconds))


def _ours_alg1(V, F, opts, clock):
    """Algorithm 1 alone from the Gauss map, the paper's Table 2 setting.

    Cotangent Laplacian, L2 gradient, no Möbius normalization, plain line search:
    ``harmonic_map(V, F, gauss_map(V, F), method="paper")``.  The timed call includes
    the Gauss map and the operator assembly.
    """
    import igl_spheremap as sm

    kw = dict(method="paper", gtol=opts.get("gtol") or 1e-5,
              max_iter=opts.get("max_iter") or 20000)
    with clock:
        res = sm.harmonic_map(V, F, sm.gauss_map(V, F), **kw)
    return dict(U=res.U, rounds=None, nit=res.nit, converged=bool(res.converged),
                message=res.message, extra=dict(called="igl_spheremap.harmonic_map",
                                                options=json_ready(kw)))


def _lapy(V, F, opts, clock, from_arrays=False):
    """LaPy 1.7: ``lapy.conformal.spherical_conformal_map(lapy.TriaMesh(V, F))``.

    Only the ``spherical_conformal_map`` call is timed (the ``TriaMesh`` is built
    before), or with ``from_arrays`` the ``TriaMesh`` construction too (LaPy's mesh
    set-up and checks, the counterpart of our input validation).  Warnings LaPy logs
    (e.g. its fallback to the spherical Tutte map) are returned in ``notes``.
    """
    import logging

    import lapy
    import lapy.conformal

    records = []

    class _Keep(logging.Handler):
        def emit(self, record):
            records.append(f"{record.levelname.lower()}: {record.getMessage()}")

    handler = _Keep(level=logging.WARNING)
    logger = logging.getLogger("lapy")
    logger.addHandler(handler)
    try:
        if from_arrays:
            with clock:
                U = lapy.conformal.spherical_conformal_map(lapy.TriaMesh(V, F))
        else:
            tria = lapy.TriaMesh(V, F)
            with clock:
                U = lapy.conformal.spherical_conformal_map(tria)
    finally:
        logger.removeHandler(handler)
    return dict(U=np.asarray(U, dtype=np.float64), rounds=None, nit=None, converged=None,
                message="", notes=records)


def _lapy_arrays(V, F, opts, clock):
    """LaPy 1.7 from arrays: ``TriaMesh(V, F)`` and ``spherical_conformal_map`` both timed."""
    return _lapy(V, F, opts, clock, from_arrays=True)


def _gu_yau(V, F, opts, clock):
    """The Gu-Yau-style baseline of benchmarks/gu_yau.py from the Gauss map."""
    import igl_spheremap as sm
    from gu_yau import gu_yau_harmonic_map
    kw = dict(gtol=opts.get("gtol") or 1e-5, max_seconds=opts.get("gu_yau_seconds", 60.0),
              max_iter=opts.get("gu_yau_max_iter", 1_000_000))
    with clock:
        r = gu_yau_harmonic_map(V, F, sm.gauss_map(V, F), **kw)
    return dict(U=r.U, rounds=None, nit=r.nit, converged=r.converged, message=r.message,
                extra=dict(step=r.step, options=kw))


#: name -> (label, function).  Labels are what the tables print.
METHODS = {
    "default": ("ours: default (folding_free)", _ours_default),
    "polish": ("ours: default with polish='always'", _ours_polish),
    "default_superlu": ("ours: default, SuperLU (no cholmod extra)", _ours_default_superlu),
    "alg1": ("ours: Alg. 1 from Gauss map (cotan, L2)", _ours_alg1),
    "paper": ("ours: Alg. 2 as published (paper)", _ours_paper),
    "lapy": ("LaPy 1.7", _lapy),
    "lapy_arrays": ("LaPy 1.7, TriaMesh(V, F) timed too", _lapy_arrays),
    "gu_yau": ("Gu-Yau baseline", _gu_yau),
}


def _checked(res, V, F):
    """The row entries of a method's result: its bookkeeping, then the map's quality."""
    U = res.pop("U")
    out = dict(res, notes=res.pop("notes", []))
    bad = int(np.count_nonzero(~np.all(np.isfinite(U), axis=1)))
    if U.shape != V.shape:
        out["status"] = f"failed: map has shape {U.shape}, expected {V.shape}"
    elif bad:
        out["status"] = f"failed: map has {bad} non-finite rows"
    else:
        out.update(quality_row(V, F, U), status="ok")
    return out


def measure_case(mesh, method, opts):
    """Child body of :func:`run_case`: load, run one method, measure; one dict."""
    out = dict(status="failed: child did not finish", seconds=None, base_rss_mib=None,
               peak_rss_mib=None, notes=[])
    clock = Clock()
    import igl_spheremap  # noqa: F401  (imported before the base RSS reading)
    V, F = load_mesh(mesh)
    out.update(vertices=int(V.shape[0]), faces=int(F.shape[0]))
    try:
        fn = METHODS[method][1]
        res, _, runs = timed_calls(lambda c: fn(V, F, opts, c), int(opts.get("repeats", REPEATS)),
                                   clock)
    except Exception as exc:  # recorded with the memory and time so far, not fatal
        out.update(status=f"failed: {type(exc).__name__}: {one_line(exc)}",
                   traceback=traceback.format_exc(limit=8), seconds=clock.seconds,
                   seconds_runs=[], base_rss_mib=clock.base_rss,
                   peak_rss_mib=clock.peak_rss if clock.peak_rss is not None else peak_rss_mib())
        return out
    out.update(seconds=min(runs), seconds_runs=runs, base_rss_mib=clock.base_rss,
               peak_rss_mib=clock.peak_rss)
    out.update(_checked(res, V, F))
    return out


def run_case(mesh, method, opts=None, timeout=600.0):
    """Run one method on one mesh in a fresh ``spawn`` child process.

    Parameters
    ----------
    mesh : path
        Mesh file (:func:`harness.load_mesh`); the child reads it itself.
    method : str
        A key of :data:`METHODS`.
    opts : dict, optional
        Method options (``gtol``, ``max_iter``, ``max_rounds``, ``gu_yau_seconds``,
        ``repeats``...).
    timeout : float
        Wall-clock limit in seconds for the whole child (start-up, loading, method,
        metrics); on expiry the child is killed and the row's status is ``"timeout"``.

    Returns
    -------
    dict
        ``status`` (``"ok"``, ``"failed: <message>"`` or ``"timeout"``), ``seconds``
        (the timed call: the best of the calls of the timing protocol), ``seconds_runs``,
        ``peak_rss_mib`` and ``base_rss_mib`` (of the first call), ``vertices``,
        ``faces``, ``rounds``, ``nit``, ``converged``, ``message``, ``notes``, the
        :func:`harness.quality_row` entries of the first call's map, ``mesh``,
        ``method`` and ``label``.
    """
    out = run_in_child(measure_case, dict(mesh=str(mesh), method=method, opts=dict(opts or {})),
                       timeout)
    out.setdefault("seconds", None)
    out.setdefault("notes", [])
    out.update(mesh=mesh_name(mesh), method=method, label=METHODS[method][0])
    return out

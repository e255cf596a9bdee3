"""Shared helpers of the benchmark scripts (not part of the library).

* finding and loading meshes (:func:`mesh_paths`, :func:`load_mesh`);
* the methods being timed (:data:`METHODS`), each a function
  ``method(V, F, opts, clock) -> dict`` that does its untimed set-up, runs the
  timed call inside ``with clock:`` and returns the map ``U`` with its
  bookkeeping (rounds, iterations, converged, message);
* the quality row of a map (:func:`quality_row`);
* the child-process runner (:func:`run_case`): every (mesh, method) pair runs
  in a fresh process started with the ``spawn`` method, so the reported peak
  memory is that process's own peak resident set size, read in the child right
  after the timed call, and a crash or a timeout of one method cannot take the
  others down; the timing protocol is the same for every method: a call that
  takes less than 10 s is repeated in the same process and the fastest of 3
  calls counts (:data:`REPEATS`, :data:`REPEAT_BELOW_SECONDS`);
* markdown / JSON output (:func:`markdown_table`, :func:`write_outputs`) and the
  run's environment (:func:`environment`).

Peak RSS is the kernel's high-water mark of the child's resident set,
``VmHWM`` in ``/proc/self/status`` (Linux).  Not ``getrusage(...).ru_maxrss``:
Linux carries ``ru_maxrss`` over ``fork`` + ``exec``, so a child spawned by a
parent holding 500 MiB reports >= 500 MiB whatever it does (and the parent's
``RUSAGE_CHILDREN`` value is the maximum over all children so far, not per
child).  ``VmHWM`` belongs to the child's own address space, created at
``exec``.  Other systems fall back to ``ru_maxrss``.  Peak RSS includes the
interpreter, numpy/scipy/libigl (and lapy for the LaPy rows) and the input
mesh; ``base RSS`` is the high-water mark just before the timed call, so
``peak - base`` is what the method itself added on top.
"""

import json
import math
import os
import platform
import resource
import subprocess
import sys
import time
import traceback
from pathlib import Path

import numpy as np

from igl_spheremap.io.write_report import json_ready

BENCH_DIR = Path(__file__).resolve().parent
REPO_ROOT = BENCH_DIR.parent
DEFAULT_MESH_DIR = REPO_ROOT.parent / "shared" / "meshes"
DEFAULT_OUT = BENCH_DIR / "results"
MESH_SUFFIXES = (".obj", ".off", ".ply", ".stl", ".gii", ".npz")


# --------------------------------------------------------------------------- meshes

def mesh_paths(items=None, default_dir=DEFAULT_MESH_DIR):
    """Mesh files named by ``items`` (files or folders), smallest file first.

    A folder stands for the meshes directly inside it; with no ``items`` the
    folder ``default_dir`` is used.

    Returns
    -------
    list of pathlib.Path

    Raises
    ------
    FileNotFoundError
        If an item does not exist or no mesh is found.
    """
    items = list(items) if items else [default_dir]
    paths = []
    for item in items:
        p = Path(item)
        if p.is_dir():
            found = [q for q in p.iterdir() if q.is_file() and q.name.lower().endswith(MESH_SUFFIXES)]
            paths.extend(sorted(found, key=lambda q: (q.stat().st_size, q.name)))
        elif p.is_file():
            paths.append(p)
        else:
            raise FileNotFoundError(f"no such mesh file or folder: '{p}'")
    if not paths:
        raise FileNotFoundError(f"no mesh files ({', '.join(MESH_SUFFIXES)}) in {items}")
    return paths


def mesh_name(path):
    """Display name of a mesh file: the file name without its extension."""
    name = Path(path).name
    for suffix in (".surf.gii",) + MESH_SUFFIXES:
        if name.lower().endswith(suffix):
            return name[: -len(suffix)]
    return Path(path).stem


def load_mesh(path):
    """Read ``(V, F)``: ``.npz`` files with arrays ``V`` and ``F`` (written by
    scaling.py), anything else with :func:`igl_spheremap.io.read_mesh` (libigl
    formats, GIfTI, FreeSurfer).

    Returns
    -------
    V : (n, 3) float64 array
    F : (m, 3) int64 array
    """
    path = Path(path)
    if path.suffix.lower() == ".npz":
        with np.load(path) as data:
            return (np.ascontiguousarray(data["V"], dtype=np.float64),
                    np.ascontiguousarray(data["F"], dtype=np.int64))
    from igl_spheremap.io import read_mesh
    V, F, _ = read_mesh(path)
    return V, F


# --------------------------------------------------------------------------- methods

class Clock:
    """Context manager around the timed call: wall time and peak RSS.

    ``base_rss`` is the process's RSS high-water mark on entry, ``peak_rss`` on
    exit (MiB, :func:`peak_rss_mib`).
    """

    seconds = None
    base_rss = None
    peak_rss = None

    def __enter__(self):
        self.base_rss = peak_rss_mib()
        self._t0 = time.perf_counter()
        return self

    def __exit__(self, *exc):
        self.seconds = time.perf_counter() - self._t0
        self.peak_rss = peak_rss_mib()
        return False


def peak_rss_mib():
    """Peak resident set size of this process so far, in MiB.

    ``VmHWM`` of ``/proc/self/status`` where it exists (see the module
    docstring for why not ``ru_maxrss``), else ``getrusage(RUSAGE_SELF).ru_maxrss``.
    """
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024.0  # kB
    except (OSError, ValueError, IndexError):
        pass
    kib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return kib / (1024.0 * 1024.0) if sys.platform == "darwin" else kib / 1024.0


def _ours_default(V, F, opts, clock):
    """Our default pipeline: ``spherical_conformal_map(V, F)`` (method "folding_free")."""
    import igl_spheremap as sm
    kw = {k: opts[k] for k in ("max_rounds", "gtol", "max_iter") if opts.get(k) is not None}
    with clock:
        r = sm.spherical_conformal_map(V, F, **kw)
    return _from_spherical_result(r)


def _ours_default_superlu(V, F, opts, clock):
    """The default pipeline as installed without the ``cholmod`` extra (H1 metric by SuperLU)."""
    for name in ("sksparse", "sksparse_minimal"):  # as if not installed (this child only)
        sys.modules[name] = None
    return _ours_default(V, F, opts, clock)


def _ours_paper(V, F, opts, clock):
    """The paper's Algorithm 2 as published: ``spherical_conformal_map(V, F, method="paper")``."""
    import igl_spheremap as sm
    kw = {k: opts[k] for k in ("max_rounds", "gtol", "max_iter") if opts.get(k) is not None}
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

    Cotangent Laplacian, L2 gradient, no Möbius normalization, plain line
    search: ``harmonic_map(V, F, gauss_map(V, F), method="paper")``.  The timed
    call includes the Gauss map and the operator assembly.
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

    Only the ``spherical_conformal_map`` call is timed (the ``TriaMesh`` is
    built before), or with ``from_arrays`` the ``TriaMesh`` construction too
    (LaPy's mesh set-up and checks, the counterpart of our input validation).
    Warnings LaPy logs (e.g. its fallback to the spherical Tutte map) are
    returned in ``notes``.
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
    "default_superlu": ("ours: default, SuperLU (no cholmod extra)", _ours_default_superlu),
    "alg1": ("ours: Alg. 1 from Gauss map (cotan, L2)", _ours_alg1),
    "paper": ("ours: Alg. 2 as published (paper)", _ours_paper),
    "lapy": ("LaPy 1.7", _lapy),
    "lapy_arrays": ("LaPy 1.7, TriaMesh(V, F) timed too", _lapy_arrays),
    "gu_yau": ("Gu-Yau baseline", _gu_yau),
}


# --------------------------------------------------------------------------- metrics

def quality_row(V, F, U):
    """Quality of a spherical map ``U`` of ``(V, F)`` with the library's metrics.

    Returns
    -------
    dict
        ``folds`` (:func:`igl_spheremap.count_folds`), ``angle_mean`` and
        ``angle_sd`` (degrees, over all corners, :func:`igl_spheremap.angle_distortion`),
        ``energy_4pi`` (:func:`igl_spheremap.harmonic_energy` with the cotangent
        Laplacian of ``(V, F)``, divided by ``4 pi``; 1 for a conformal
        bijection), ``centroid_norm`` (norm of
        :func:`igl_spheremap.image_centroid`), ``max_radius_error``
        (``max | |U_i| - 1 |``), and ``angle_mean_centered`` /
        ``angle_sd_centered``: the angle distortion of the same map after
        Möbius centering (:func:`igl_spheremap.mobius_center` with the input's
        barycentric vertex areas).  The flat-triangle angles depend on which
        of the Möbius-equivalent conformal maps a method returns, so this is
        the like-for-like number for methods that do not normalize (LaPy);
        ``None`` if centering fails (e.g. a map collapsed to a point).
    """
    import igl_spheremap as sm
    from igl_spheremap.operators import vertex_areas
    ang = sm.angle_distortion(V, F, U)
    row = dict(folds=sm.count_folds(F, U), angle_mean=float(ang.mean()),
               angle_sd=float(ang.std()),
               energy_4pi=sm.harmonic_energy(V, F, U) / (4.0 * math.pi),
               centroid_norm=float(np.linalg.norm(sm.image_centroid(V, F, U))),
               max_radius_error=float(np.abs(np.linalg.norm(U, axis=1) - 1.0).max()),
               angle_mean_centered=None, angle_sd_centered=None)
    try:
        Uc, mu = sm.mobius_center(U, vertex_areas(V, F))
        if mu < 1e-6 and np.all(np.isfinite(Uc)):
            ang = sm.angle_distortion(V, F, Uc)
            row.update(angle_mean_centered=float(ang.mean()), angle_sd_centered=float(ang.std()))
    except (ValueError, np.linalg.LinAlgError):
        pass
    return row


# --------------------------------------------------------------------------- child process

def _case(mesh, method, opts):
    """Body of :func:`run_case`'s child process: load, run one method, measure; one dict."""
    out = dict(status="failed: child did not finish", seconds=None, base_rss_mib=None,
               peak_rss_mib=None, notes=[])
    clock = Clock()
    try:
        sys.path.insert(0, str(BENCH_DIR))
        import igl_spheremap  # noqa: F401  (imported before the base RSS reading)
        V, F = load_mesh(mesh)
        out.update(vertices=int(V.shape[0]), faces=int(F.shape[0]))
        _, fn = METHODS[method]
        runs = []
        try:
            res = fn(V, F, opts, clock)
            runs.append(clock.seconds)
            repeats = int(opts.get("repeats", REPEATS))
            while len(runs) < repeats and runs[0] < REPEAT_BELOW_SECONDS:
                again = Clock()
                fn(V, F, opts, again)
                runs.append(again.seconds)
        except Exception as exc:  # recorded, not fatal
            out.update(status=f"failed: {type(exc).__name__}: {_one_line(exc)}",
                       traceback=traceback.format_exc(limit=8))
            res = None
        out.update(seconds=min(runs) if res is not None else clock.seconds, seconds_runs=runs,
                   base_rss_mib=clock.base_rss,
                   peak_rss_mib=clock.peak_rss if clock.peak_rss is not None else peak_rss_mib())
        if res is not None:
            U = res.pop("U")
            out["notes"] = res.pop("notes", [])
            out.update(res)
            bad = int(np.count_nonzero(~np.all(np.isfinite(U), axis=1)))
            if U.shape != V.shape:
                out["status"] = f"failed: map has shape {U.shape}, expected {V.shape}"
            elif bad:
                out["status"] = f"failed: map has {bad} non-finite rows"
            else:
                out.update(quality_row(V, F, U))
                out["status"] = "ok"
    except Exception as exc:
        out.update(status=f"failed: {type(exc).__name__}: {_one_line(exc)}",
                   traceback=traceback.format_exc(limit=8))
    return out


#: Timing protocol: a call that takes less than :data:`REPEAT_BELOW_SECONDS`
#: is repeated in the same child until :data:`REPEATS` calls ran, and the
#: fastest counts (the machine is shared and noisy); a longer call runs once.
#: Every method is timed the same way.  ``opts["repeats"]`` overrides REPEATS.
REPEATS = 3
REPEAT_BELOW_SECONDS = 10.0


def run_case(mesh, method, opts=None, timeout=600.0):
    """Run one method on one mesh in a fresh ``spawn`` child process.

    Parameters
    ----------
    mesh : path
        Mesh file (see :func:`load_mesh`); the child reads it itself.
    method : str
        A key of :data:`METHODS`.
    opts : dict, optional
        Method options (``gtol``, ``max_iter``, ``max_rounds``, ``gu_yau_seconds``...).
    timeout : float
        Wall-clock limit in seconds for the whole child (start-up, loading,
        method, metrics).  On expiry the child is killed and the row's status
        is ``"timeout"``.

    Returns
    -------
    dict
        ``status`` is ``"ok"``, ``"failed: <message>"`` or ``"timeout"``;
        ``seconds`` (timed call only: the best of :data:`REPEATS` calls when
        the first takes less than :data:`REPEAT_BELOW_SECONDS`, else the one
        call), ``seconds_runs`` (every call's time), ``peak_rss_mib`` and
        ``base_rss_mib`` (of the first call), the map's quality from the
        first call, ``vertices``, ``faces``,
        ``rounds``, ``nit``, ``converged``, ``message``, ``notes`` and the
        :func:`quality_row` entries.
    """
    from _child import run_in_child  # _child imports this module

    out = run_in_child(_case, dict(mesh=str(mesh), method=method, opts=dict(opts or {})), timeout)
    out.setdefault("seconds", None)
    out.setdefault("notes", [])
    out.update(mesh=mesh_name(mesh), method=method, label=METHODS[method][0])
    return out


# --------------------------------------------------------------------------- output

def fmt(value, spec="", none="–"):
    """Format a table cell: ``None``/NaN as ``none``, bools as yes/no."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return none
    if isinstance(value, bool):
        return "yes" if value else "no"
    if spec:
        return format(value, spec)
    return str(value)


def markdown_table(rows, columns):
    """Markdown table of ``rows`` (dicts).

    ``columns`` is a list of ``(header, key_or_callable, spec, align)``; a
    callable gets the row and returns the cell text; ``align`` is ``"l"`` or ``"r"``.
    """
    head = "| " + " | ".join(c[0] for c in columns) + " |"
    rule = "|" + "|".join("---:" if c[3] == "r" else "---" for c in columns) + "|"
    lines = [head, rule]
    for row in rows:
        cells = []
        for _, key, spec, _ in columns:
            cells.append(str(key(row)) if callable(key) else fmt(row.get(key), spec))
        lines.append("| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |")
    return "\n".join(lines)


def status_cell(row, width=70):
    """Status text for a table: ``ok``, ``timeout`` or a shortened failure message."""
    s = row.get("status", "")
    return s if len(s) <= width else s[: width - 1] + "…"


def environment():
    """Machine and software versions, recorded with every result file."""
    import importlib.metadata as md
    env = dict(python=platform.python_version(), platform=platform.platform(),
               cpu=_cpu_model(), cpu_count=os.cpu_count(),
               load_average=list(os.getloadavg()) if hasattr(os, "getloadavg") else None,
               date=time.strftime("%Y-%m-%d %H:%M:%S %z"))
    for pkg in ("igl-spheremap", "libigl", "numpy", "scipy", "pyamg", "scikit-sparse",
                "sksparse-minimal", "lapy", "matplotlib"):
        try:
            env[pkg] = md.version(pkg)
        except md.PackageNotFoundError:
            env[pkg] = None
    try:
        env["git_commit"] = subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"], cwd=REPO_ROOT, capture_output=True,
            text=True, timeout=10).stdout.strip() or None
        dirty = subprocess.run(["git", "status", "--porcelain", "--", "igl_spheremap"],
                               cwd=REPO_ROOT, capture_output=True, text=True, timeout=10).stdout
        env["library_modified_since_commit"] = bool(dirty.strip())
    except (OSError, subprocess.SubprocessError):
        env["git_commit"] = None
    return env


def _cholmod_line(env):
    """Which CHOLMOD package the run had (the H1 metric's direct backend), or that it had none."""
    for pkg in ("scikit-sparse", "sksparse-minimal"):
        if env.get(pkg):
            return f"CHOLMOD from {pkg} {env[pkg]}"
    return "no CHOLMOD (SuperLU)"


def environment_line(env):
    """One markdown line summarising :func:`environment`."""
    return (f"igl-spheremap {env.get('igl-spheremap')} (git {env.get('git_commit')}"
            f"{', library modified' if env.get('library_modified_since_commit') else ''}), "
            f"libigl {env.get('libigl')}, LaPy {env.get('lapy')}, numpy {env.get('numpy')}, "
            f"scipy {env.get('scipy')}, {_cholmod_line(env)}, "
            f"Python {env.get('python')}; {env.get('cpu')}, "
            f"{env.get('cpu_count')} logical CPUs, load average at start "
            f"{', '.join(f'{x:.1f}' for x in env.get('load_average') or [])}; {env.get('date')}.")


def _cpu_model():
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or None


def write_outputs(out_dir, stem, markdown, payload):
    """Write ``out_dir/stem.md`` and ``out_dir/stem.json`` (each atomically)."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    _atomic_write(out_dir / f"{stem}.md", markdown + "\n")
    _atomic_write(out_dir / f"{stem}.json", json.dumps(json_ready(payload), indent=1) + "\n")
    return out_dir / f"{stem}.md", out_dir / f"{stem}.json"


def _atomic_write(path, text):
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp{os.getpid()}")
    tmp.write_text(text)
    os.replace(tmp, path)


def _one_line(exc, width=300):
    text = " ".join(str(exc).split())
    return text if len(text) <= width else text[: width - 1] + "…"

"""The benchmark harness: what every script of ``benchmarks/`` shares (not part of the library).

* Meshes: :func:`mesh_paths` (files or folders, smallest file first), :func:`mesh_name`,
  :func:`load_mesh`.
* Measuring: :class:`Clock` (wall time and peak RSS around the timed call),
  :func:`peak_rss_mib`, the timing protocol (:func:`timed_calls`, :data:`REPEATS`,
  :data:`REPEAT_BELOW_SECONDS`) and :func:`quality_row` (the quality of a map).
* Child processes: :func:`run_in_child` runs a module-level function in a fresh
  ``spawn`` process with a time limit; a crash, an exception or a timeout becomes
  the row's ``status`` instead of stopping the run.  The map methods of the
  comparison (:mod:`methods`) run through it.
* Output: :func:`markdown_table`, :func:`fmt`, :func:`status_cell`,
  :func:`environment` / :func:`environment_line` (machine and versions, recorded
  with every result) and :func:`write_outputs` (``<name>.md`` and ``<name>.json``).
* The script skeleton: :func:`arguments` (the common command-line arguments),
  :func:`run` (cases -> rows -> ``results/<name>.md`` + ``.json`` after every case,
  then the markdown on stdout), :func:`page` and :func:`command`.

Peak RSS is ``VmHWM`` of ``/proc/self/status`` (Linux), not ``ru_maxrss``, which Linux
carries over ``fork`` + ``exec`` (a child of a 500 MiB parent reports >= 500 MiB);
other systems fall back to ``ru_maxrss``.  It includes the interpreter, the libraries
and the mesh; ``base RSS`` is the high-water mark just before the timed call, so
``peak - base`` is what the call itself added.

Scripts run as ``python benchmarks/<script>.py``: Python puts the script's folder
first on its module search path, so ``import harness`` works, and ``spawn`` children
start with the parent's search path, so a child target is found by its module-level
name.  No script edits the search path.
"""

import argparse
import json
import math
import multiprocessing as mp
import os
import platform
import resource
import subprocess
import sys
import time
import traceback
from pathlib import Path

import numpy as np

from igl_spheremap.io.atomic import atomic_path
from igl_spheremap.io.mesh_format import GIFTI_SUFFIXES
from igl_spheremap.io.write_report import json_ready

BENCH_DIR = Path(__file__).resolve().parent
REPO_ROOT = BENCH_DIR.parent
DEFAULT_MESH_DIR = REPO_ROOT.parent / "shared" / "meshes"
"""The 14 shared closed genus-0 meshes, next to the repository (not in it)."""
DEFAULT_OUT = BENCH_DIR / "results"
MESH_SUFFIXES = (".obj", ".off", ".ply", ".stl", *GIFTI_SUFFIXES, ".npz")

#: Timing protocol: a call that takes less than :data:`REPEAT_BELOW_SECONDS` is
#: repeated in the same process until :data:`REPEATS` calls ran, and the fastest
#: counts (the machine is shared and noisy); a longer call runs once.
REPEATS = 3
REPEAT_BELOW_SECONDS = 10.0


# --------------------------------------------------------------------------- meshes

def mesh_paths(items=None, default_dir=DEFAULT_MESH_DIR):
    """Mesh files named by ``items`` (files or folders), smallest file first per folder.

    A folder stands for the meshes directly inside it; with no ``items`` the folder
    ``default_dir`` is used.

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
            found = [q for q in p.iterdir()
                     if q.is_file() and q.name.lower().endswith(MESH_SUFFIXES)]
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
    for suffix in (".surf.gii", ".surf.gii.gz") + MESH_SUFFIXES:
        if name.lower().endswith(suffix):
            return name[: -len(suffix)]
    return Path(path).stem


def load_mesh(path):
    """``(V, F)`` as float64 (n, 3) and int64 (m, 3): ``.npz`` files with arrays ``V`` and
    ``F`` (the generated meshes of :mod:`remesh`), anything else with
    :func:`igl_spheremap.io.read_mesh` (libigl formats, GIfTI, FreeSurfer)."""
    path = Path(path)
    if path.suffix.lower() == ".npz":
        with np.load(path) as data:
            return (np.ascontiguousarray(data["V"], dtype=np.float64),
                    np.ascontiguousarray(data["F"], dtype=np.int64))
    from igl_spheremap.io import read_mesh
    V, F, _ = read_mesh(path)
    return V, F


# --------------------------------------------------------------------------- measuring

class Clock:
    """Context manager around the timed call: ``seconds`` and ``base_rss`` / ``peak_rss``
    (the process's RSS high-water mark on entry / on exit, MiB)."""

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
    """Peak resident set size of this process so far, in MiB (``VmHWM``, else ``ru_maxrss``)."""
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024.0  # kB
    except (OSError, ValueError, IndexError):
        pass
    kib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return kib / (1024.0 * 1024.0) if sys.platform == "darwin" else kib / 1024.0


def timed_calls(call, repeats=REPEATS, clock=None):
    """The timing protocol: ``call(clock)`` (which times itself ``with clock:``) once, then
    again while the first call took under :data:`REPEAT_BELOW_SECONDS`, until ``repeats``
    calls ran.

    Returns ``(first, clock, runs)``: what the first call returned (quality is measured
    on it), its clock (``clock`` if given: its readings survive an exception) and every
    call's seconds (``min(runs)`` is the time reported).
    """
    clock = clock or Clock()
    first = call(clock)
    runs = [clock.seconds]
    while len(runs) < repeats and runs[0] < REPEAT_BELOW_SECONDS:
        again = Clock()
        call(again)
        runs.append(again.seconds)
    return first, clock, runs


def quality_row(V, F, U):
    """Quality of a spherical map ``U`` of ``(V, F)`` with the library's measures.

    Returns
    -------
    dict
        ``folds`` (``count_folds``), ``angle_mean`` and ``angle_sd`` (degrees, over all
        corners, ``angle_distortion``), ``energy_4pi`` (``harmonic_energy`` with the
        cotangent Laplacian of ``(V, F)`` over ``4 pi``; 1 for a conformal bijection),
        ``centroid_norm`` (norm of ``image_centroid``), ``max_radius_error``
        (``max | |U_i| - 1 |``), and ``angle_mean_centered`` / ``angle_sd_centered``:
        the angle distortion after Möbius centering (``mobius_center`` with the
        input's barycentric vertex areas).  Flat-triangle angles depend on which of
        the Möbius-equivalent maps a method returns, so this is the like-for-like
        number for methods that do not normalize (LaPy); ``None`` if centering fails
        (e.g. a map collapsed to a point).
    """
    import igl_spheremap as sm
    from igl_spheremap.mesh.operators import vertex_areas
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


# --------------------------------------------------------------------------- child processes

class Stop(BaseException):
    """Raised in a :func:`run_in_child` child when the parent asks it to stop (SIGTERM).

    A ``BaseException``, like ``KeyboardInterrupt``, so that the library's ``except
    Exception`` fallbacks do not swallow it."""


def _stop_handler(pid):
    """SIGTERM handler of the child ``pid``: raise :class:`Stop` there; in a process the library
    forked from it (a background worker it terminates), exit quietly as SIGTERM would."""
    import signal

    def handler(*_):
        if os.getpid() != pid:
            os._exit(128 + signal.SIGTERM)
        raise Stop("stopped by the parent's time limit")
    return handler


def _child_main(conn, target, kwargs):
    import signal
    signal.signal(signal.SIGTERM, _stop_handler(os.getpid()))
    try:
        out = dict(target(**kwargs))
        out.setdefault("status", "ok")
    except Stop as exc:
        out = dict(status="timeout", notes=[str(exc)])
    except Exception as exc:  # reported in the row, not fatal
        out = dict(status=f"failed: {type(exc).__name__}: {one_line(exc)}",
                   traceback=traceback.format_exc(limit=10))
    conn.send(json_ready(out))
    conn.close()


def run_in_child(target, kwargs, timeout=600.0, grace=0.0):
    """``target(**kwargs)`` in a fresh ``spawn`` child process, bounded by ``timeout`` seconds.

    Parameters
    ----------
    target : callable
        A module-level function (pickled by reference) returning a dict.
    kwargs : dict
        Its keyword arguments (picklable; pass file paths, not big arrays).
    timeout : float
        Wall-clock limit of the whole child.  On expiry, with ``grace > 0`` the child
        gets SIGTERM, which raises :class:`Stop` in it when Python code next runs (a
        target may catch it and return what it measured so far), and ``grace`` more
        seconds to answer; then (or at once without grace) it is killed.

    Returns
    -------
    dict
        What ``target`` returned, with ``status`` ``"ok"`` unless it set one; or
        ``status`` ``"failed: ..."`` (an exception, with ``traceback``; or the child
        died, e.g. killed for memory) or ``"timeout"``.  ``wall_seconds`` is the
        child's whole life (start-up, loading, the calls, the metrics).
    """
    ctx = mp.get_context("spawn")
    recv, send = ctx.Pipe(duplex=False)
    # not daemonic: a daemonic process may not start processes, and the library's side-by-side
    # stages would then run in the child alone (this function joins or kills the child itself)
    proc = ctx.Process(target=_child_main, args=(send, target, dict(kwargs)), daemon=False)
    t0 = time.perf_counter()
    proc.start()
    send.close()
    late = not recv.poll(timeout)  # poll is also true once the child died (end of file)
    if late and grace > 0 and proc.is_alive():
        proc.terminate()
        late = not recv.poll(grace)
    try:
        out = None if late else recv.recv()
    except EOFError:
        out = None
    elapsed = time.perf_counter() - t0
    proc.join(0 if late else 30)
    if proc.is_alive():
        proc.kill()
        proc.join()
    recv.close()
    if out is None and (late or grace > 0 and elapsed >= timeout):
        out = dict(status="timeout", notes=[f"killed after {timeout:g} s"])
    elif out is None:
        code = proc.exitcode
        why = (f"killed by signal {-code} (out of memory?)" if code and code < 0
               else f"exit code {code}")
        out = dict(status=f"failed: child process died ({why})")
    out["wall_seconds"] = elapsed
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

    ``columns`` is a list of ``(header, key_or_callable, spec, align)``; a callable gets
    the row and returns the cell text; ``align`` is ``"l"`` or ``"r"``.
    """
    head = "| " + " | ".join(c[0] for c in columns) + " |"
    rule = "|" + "|".join("---:" if c[3] == "r" else "---" for c in columns) + "|"
    lines = [head, rule]
    for row in rows:
        cells = [str(key(row)) if callable(key) else fmt(row.get(key), spec)
                 for _, key, spec, _ in columns]
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
    """Write ``out_dir/stem.md`` and ``out_dir/stem.json`` (each atomically); their paths."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    files = {out_dir / f"{stem}.md": markdown + "\n",
             out_dir / f"{stem}.json": json.dumps(json_ready(payload), indent=1) + "\n"}
    for path, text in files.items():
        with atomic_path(path) as tmp:
            tmp.write_text(text, encoding="utf-8")
    return tuple(files)


def one_line(exc, width=300):
    """An exception's message on one line, at most ``width`` characters."""
    text = " ".join(str(exc).split())
    return text if len(text) <= width else text[: width - 1] + "…"


# --------------------------------------------------------------------------- the script skeleton

def arguments(doc, *, meshes="*", mesh_help=None, out=DEFAULT_OUT, timeout=None, repeats=None):
    """An ``argparse`` parser with the arguments the scripts share.

    Parameters
    ----------
    doc : str
        The script's module docstring: its first paragraph is the description, and
        the whole of it is shown under ``--help``.
    meshes : str or None
        ``nargs`` of the positional ``meshes`` (mesh files or folders, default: the
        shared meshes); ``None`` for no positional meshes.
    out : path or None
        Default of ``--out DIR`` (the output folder); ``None`` leaves the option to the
        script.
    timeout, repeats : float, int or None
        Defaults of ``--timeout S`` (seconds per child process) and ``--repeats N``;
        ``None`` leaves the option out.

    The script adds its own options to the parser and reads it with :func:`parse`.
    """
    head, _, rest = doc.strip().partition("\n\n")
    p = argparse.ArgumentParser(description=head, epilog=rest or None,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    if meshes is not None:
        p.add_argument("meshes", nargs=meshes, metavar="MESH",
                       help=mesh_help or f"mesh files or folders (default: {DEFAULT_MESH_DIR})")
    if out is not None:
        p.add_argument("--out", type=Path, default=Path(out), metavar="DIR",
                       help="output folder (default: %(default)s)")
    if timeout is not None:
        p.add_argument("--timeout", type=float, default=timeout, metavar="S",
                       help="wall-clock limit per child process, in seconds (default: %(default)s)")
    if repeats is not None:
        p.add_argument("--repeats", type=int, default=repeats, metavar="N",
                       help="timed calls; the fastest counts (default: %(default)s)")
    return p


def parse(parser, argv=None):
    """``parser.parse_args(argv)`` with the command's own arguments kept in ``args.argv``."""
    args = parser.parse_args(argv)
    args.argv = list(sys.argv[1:] if argv is None else argv)
    return args


def command(name, args):
    """The line ``Command: `python benchmarks/<name>.py ...``` of a result page."""
    return f"Command: `python benchmarks/{name}.py" + "".join(f" {a}" for a in args.argv) + "`"


def page(title, env, *blocks):
    """A result page: ``# title``, the environment line, then the blocks (markdown), each
    block separated by a blank line; empty blocks are left out."""
    return "\n\n".join([f"# {title}", environment_line(env)] + [b.strip("\n") for b in blocks if b])


def run(name, args, cases, measure, render, *, echo=None, payload=None, out=None, env=None):
    """The skeleton of a benchmark script.

    For each case of ``cases`` (mesh paths, sizes, ...): ``measure(case)`` gives a row
    (dict) or a list of rows; ``echo(row)`` (optional) a progress line for stderr; then
    ``render(rows, env, args)`` the markdown page of all rows so far, written to
    ``<out>/<name>.md``, and ``environment``, ``options`` (the arguments but
    ``args.argv`` and those whose name starts with ``_``), ``rows`` and
    ``payload(rows)`` (optional extra entries, or replacements) to ``<out>/<name>.json``
    (``out`` default ``args.out``).  Files are rewritten after every case, so an
    interrupted run keeps what it has.  At the end the page is printed.  ``env`` is
    :func:`environment` unless given.  Returns the rows.
    """
    env, rows, t0 = env or environment(), [], time.perf_counter()
    out = Path(out if out is not None else args.out)
    markdown = None
    for case in cases:
        got = measure(case)
        got = [got] if isinstance(got, dict) else list(got)
        rows.extend(got)
        for row in got if echo else ():
            print(f"[{time.perf_counter() - t0:7.1f} s] {echo(row)}", file=sys.stderr, flush=True)
        markdown = save(name, out, rows, env, args, render, payload)
    if markdown is None:
        markdown = save(name, out, rows, env, args, render, payload)
    print(markdown)
    return rows


def save(name, out, rows, env, args, render, payload=None):
    """Render ``rows`` and write ``<out>/<name>.md`` / ``.json`` (see :func:`run`); the markdown."""
    Path(out).mkdir(parents=True, exist_ok=True)  # before render: it may write figures there
    markdown = render(rows, env, args)
    options = {k: v for k, v in vars(args).items() if k != "argv" and not k.startswith("_")}
    data = dict(environment=env, options=options, rows=rows)
    data.update(payload(rows) if payload else {})
    write_outputs(out, name, markdown, data)
    return markdown

"""Map many mesh files in parallel on Dask, resumably, with per-mesh failure isolation.

Dask is imported only inside :func:`map_batch` (``pip install igl-spheremap[batch]``).

Output layout
-------------
Outputs mirror the inputs' directories relative to their deepest common
directory, so equal file names in different folders never collide::

    subjects/A/surf/lh.white  ->  OUTDIR/A/surf/lh.white_sphere  (+ .json, .func.gii)
    subjects/B/surf/lh.white  ->  OUTDIR/B/surf/lh.white_sphere

    meshes/dino.obj, meshes/fish.obj  ->  OUTDIR/dino_sphere.obj, OUTDIR/fish_sphere.obj

Every mesh gets a JSON report ``<sphere base>.json`` written after its other
outputs; OUTDIR gets ``summary.csv`` and ``summary.md``.
"""

import csv
import glob
import io as _io
import json
import logging
import os
import sys
import time
import uuid
from dataclasses import dataclass
from pathlib import Path

from ..errors import describe
from ..io import file_digest, is_freesurfer_surface, mesh_format, output_paths
from ..io.atomic import atomic_path
from ..options import map_options
from .map_file import map_file
from .storage import default_radius, storage_options

#: Columns of ``summary.csv`` / ``summary.md``, in order.
SUMMARY_COLUMNS = ("mesh", "vertices", "faces", "folds", "converged",
                   "angle_distortion_mean_deg", "angle_distortion_sd_deg", "energy_over_4pi",
                   "seconds", "status", "message", "output")

@dataclass(frozen=True)
class _Job:
    label: str      # the input as the user gave it
    input: str      # absolute path
    sphere: str
    report: str
    data: str


def batch_output_paths(paths, outdir):
    """Sphere paths for ``paths`` under ``outdir``, mirroring their relative folders.

    Folders are taken relative to the deepest directory containing every input
    (``os.path.commonpath`` of the absolute parents; symlinks are not resolved).
    If the inputs share no common directory (different drives), the absolute
    folder without its root is used.

    Parameters
    ----------
    paths : sequence of str or os.PathLike
    outdir : str or os.PathLike

    Returns
    -------
    list of igl_spheremap.io.OutputPaths
        One per input, in order.
    """
    absolute = [Path(os.path.abspath(p)) for p in paths]
    try:
        common = Path(os.path.commonpath([str(p.parent) for p in absolute])) if absolute else None
    except ValueError:
        common = None
    out = []
    for p in absolute:
        rel = p.parent.relative_to(common) if common else Path(*p.parent.parts[1:])
        out.append(output_paths(p, outdir=Path(outdir) / rel))
    return out


def _finished_report(job, options, radius, data, file_precision):
    """The job's report if it says complete, used the same options and its input and outputs
    are the files it recorded (SHA-256 digests: an input replaced or an output damaged since
    is mapped again), else None."""
    try:
        rep = json.loads(Path(job.report).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(rep, dict) or rep.get("complete") is not True:
        return None
    if rep.get("input") != job.input or not Path(job.sphere).is_file():
        return None
    if data and not Path(job.data).is_file():
        return None
    digests = rep.get("digests") or {}
    files = {"input": job.input, "sphere": job.sphere, **({"data": job.data} if data else {})}
    if any(digests.get(key) is None or digests[key] != file_digest(path)
           for key, path in files.items()):
        return None
    done = rep.get("options", {})
    if radius is None:
        radius = default_radius(done.get("output_family"))
    options = storage_options(options, job.sphere, done.get("output_family"), file_precision)
    wanted = {**options.to_dict(), "radius": float(radius), "file_precision": file_precision}
    if any(done.get(key) != value for key, value in wanted.items()):
        return None
    return rep


def batch_inputs(items):
    """The mesh files named by ``items``: files as given, folders by the mesh files directly in
    them, glob patterns (not expanded by a shell) by their matches.

    A folder's mesh files are those :func:`igl_spheremap.io.mesh_format` names, except
    that a FreeSurfer one must be a surface by its content
    (:func:`igl_spheremap.io.is_freesurfer_surface`): the morphometry files (``lh.sulc``,
    ``lh.thickness``), ``.mgh``, ``.label`` and report files beside the surfaces in a
    ``surf/`` folder are skipped, as any other file that is no mesh.

    An item that names nothing (a missing file, an empty folder, a pattern with no
    match) is kept: its row fails alone, with a message saying so.

    Parameters
    ----------
    items : sequence of str or os.PathLike

    Returns
    -------
    list of str
    """
    out = []
    for item in map(str, items):
        path = Path(item)
        if path.is_dir():
            found = sorted(str(q) for q in path.iterdir() if q.is_file() and _is_mesh(q))
        elif not path.exists() and glob.has_magic(item):
            found = sorted(glob.glob(item))
        else:
            found = []
        out.extend(found or [item])
    return out


def _is_mesh(path):
    family = mesh_format(path, must_exist=False)
    return family is not None and (family != "freesurfer" or is_freesurfer_surface(path))


def _jobs(paths, outdir):
    """One job per distinct input (absolute path), labelled as the user gave it."""
    unique = list(dict.fromkeys(os.path.abspath(p) for p in paths))
    labels = {}
    for p in paths:
        labels.setdefault(os.path.abspath(p), str(p))
    return [_Job(labels[a], a, str(o.sphere), str(o.report), str(o.data))
            for a, o in zip(unique, batch_output_paths(unique, outdir))]


def _collision(jobs, i):
    """Why job ``i`` must not run (an output of an earlier job has its name), or None.

    ``a/x.obj`` and ``a/x.off`` both report to ``x_sphere.json``: the second
    would overwrite the first one's report.
    """
    mine = {job_path for job_path in (jobs[i].sphere, jobs[i].report, jobs[i].data)}
    for other in jobs[:i]:
        shared = mine & {other.sphere, other.report, other.data}
        if shared:
            return (f"its output {os.path.basename(sorted(shared)[0])} would overwrite that of "
                    f"{other.label}; map one of them separately")
    return None


def _run_on_dask(jobs, todo, task, rows, scheduler, n_workers, progress, on_result):
    """Map the jobs ``todo`` on a Dask cluster; fill ``rows`` as they finish."""
    from dask.distributed import as_completed
    from tqdm.auto import tqdm

    workers = max(1, min(n_workers or 2, len(todo)))
    with _Cluster(scheduler, workers) as client:
        token = uuid.uuid4().hex[:8]
        futures = {client.submit(_map_one, jobs[i], *task, pure=False,
                                 key=f"igl-spheremap-{token}-{i}"): i for i in todo}
        with tqdm(total=len(futures), disable=not progress, file=sys.stderr,
                  unit="mesh", desc="mapping") as bar:
            for fut in as_completed(futures):
                i = futures[fut]
                try:
                    rows[i] = fut.result()
                except Exception as exc:  # the task itself failed (e.g. worker killed)
                    rows[i] = _failure_row(jobs[i], exc, task[-1])
                bar.update()
                if on_result is not None:
                    on_result(rows[i])


def _row(job, rep, status, outdir):
    return {"mesh": job.label, "vertices": rep.get("vertices"), "faces": rep.get("faces"),
            "folds": rep.get("folds"), "converged": rep.get("converged"),
            "angle_distortion_mean_deg": rep.get("angle_distortion_mean_deg"),
            "angle_distortion_sd_deg": rep.get("angle_distortion_sd_deg"),
            "energy_over_4pi": rep.get("energy_over_4pi"),
            "seconds": rep.get("timings", {}).get("total"), "status": status,
            "message": rep.get("message", ""), "output": os.path.relpath(job.sphere, outdir),
            "success": bool(rep.get("success"))}


def _failure_row(job, exc, outdir):
    row = dict.fromkeys(SUMMARY_COLUMNS)
    row.update(mesh=job.label, status="failed", message=describe(exc),
               output=os.path.relpath(job.sphere, outdir), success=False)
    return row


def _map_one(job, options, radius, data, file_precision, hemisphere, outdir):
    """Worker task: map one mesh; any exception becomes a failure row."""
    t0 = time.perf_counter()
    try:
        if glob.has_magic(job.label) and not Path(job.input).exists():
            raise FileNotFoundError(f"'{job.label}' matches no file")
        if Path(job.input).is_dir():
            raise IsADirectoryError(f"'{job.label}' is a folder with no mesh file in it")
        rep = map_file(job.input, job.sphere, options=options, report=job.report, data=data,
                       data_path=job.data, radius=radius, file_precision=file_precision,
                       hemisphere=hemisphere)
    except Exception as exc:  # isolate this mesh's failure from the batch
        row = _failure_row(job, exc, outdir)
        row["seconds"] = time.perf_counter() - t0
        return row
    return _row(job, rep, "ok" if rep["success"] else "warning", outdir)


class _Cluster:
    """A Dask client on ``scheduler``, or on a LocalCluster that is shut down afterwards."""

    def __init__(self, scheduler, n_workers):
        self.scheduler, self.n_workers = scheduler, n_workers
        self.cluster = self.client = None

    def __enter__(self):
        from dask.distributed import Client, LocalCluster

        if self.scheduler:
            self.client = Client(self.scheduler)
        else:
            # no dashboard; the scheduler's HTTP server (started anyway) on a free local
            # port, not 8787, which a running Jupyter or cluster may hold (a warning then)
            self.cluster = LocalCluster(n_workers=self.n_workers, threads_per_worker=1,
                                        processes=True, dashboard_address=None,
                                        scheduler_kwargs={"dashboard": False,
                                                          "dashboard_address": "127.0.0.1:0"},
                                        silence_logs=logging.ERROR)
            self.client = Client(self.cluster)
        return self.client

    def __exit__(self, *exc):
        self.client.close()
        if self.cluster is not None:
            self.cluster.close()


def map_batch(paths, outdir, scheduler=None, n_workers=None, resume=True, *, options=None,
              data=False, radius=None, file_precision=None, hemisphere=None, progress=False,
              on_result=None, **option_values):
    """Map mesh files in parallel on a Dask cluster; write outputs, reports and a summary.

    Each mesh is one task running :func:`igl_spheremap.app.map_file.map_file`, so its
    outputs are written atomically by the worker and its JSON report last.  A
    mesh whose report exists, says ``"complete": true``, names the same input
    and requested options, and whose sphere (and data file, if requested)
    exists, is not recomputed when ``resume`` (its row has status
    ``"skipped"`` and the numbers of the earlier run).  Any exception in a task
    (invalid mesh, unreadable file, a worker that died) becomes a row with
    status ``"failed"`` and the message; other meshes go on.

    Parameters
    ----------
    paths : sequence of str or os.PathLike
        Mesh files (any format :func:`igl_spheremap.io.read_mesh` reads), folders
        and glob patterns (:func:`batch_inputs`); duplicates are mapped once.  Workers must see the same paths (shared
        filesystem when ``scheduler`` is remote).
    outdir : str or os.PathLike
        Created if needed; layout in the module docstring.
    scheduler : str, optional
        Address of a running Dask scheduler (``tcp://host:8786``).  Default: a
        new ``LocalCluster`` of ``n_workers`` processes with one thread each.
    n_workers : int, optional
        LocalCluster size (default 2, at most the number of meshes to map).
    resume : bool, default True
        Skip meshes already mapped (see above).
    options : MapOptions or dict, optional
        Options of every map (:class:`igl_spheremap.MapOptions`).
    data : bool, default False
        Also write per-vertex data.
    radius, file_precision, hemisphere : optional
        As in :func:`igl_spheremap.app.map_file.map_file`.
    progress : bool, default False
        tqdm progress bar on stderr over finished meshes.
    on_result : callable, optional
        Called with each row as it is known.
    **option_values
        Fields of :class:`igl_spheremap.MapOptions`; they override ``options``.

    Returns
    -------
    list of dict
        One row per distinct input, in input order, with the keys of
        :data:`SUMMARY_COLUMNS` (numbers as floats/ints, ``None`` when
        unknown) plus ``success`` (bool).  ``status`` is ``"ok"`` (no folds,
        converged), ``"warning"`` (outputs written but folds remain or the
        optimizer did not converge), ``"skipped"`` or ``"failed"``.
    """
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    jobs = _jobs(batch_inputs(paths), outdir)
    options = map_options(options, **option_values)
    rows = [None] * len(jobs)
    todo = []
    for i, job in enumerate(jobs):
        clash = _collision(jobs, i)
        rep = None if clash or not resume else _finished_report(job, options, radius, data,
                                                                file_precision)
        if clash:
            rows[i] = _failure_row(job, ValueError(clash), outdir)
        elif rep is not None:
            rows[i] = _row(job, rep, "skipped", outdir)
        else:
            todo.append(i)
            continue
        if on_result is not None:
            on_result(rows[i])
    if todo:
        task = (options, radius, bool(data), file_precision, hemisphere, str(outdir))
        _run_on_dask(jobs, todo, task, rows, scheduler, n_workers, progress, on_result)
    write_summary(rows, outdir)
    return rows


def _fmt(value):
    if value is None:
        return ""
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return f"{value:.4g}"
    return str(value)


def summary_markdown(rows):
    """The summary rows as a GitHub-flavoured markdown table (str)."""
    lines = ["| " + " | ".join(SUMMARY_COLUMNS) + " |",
             "|" + "|".join("---" for _ in SUMMARY_COLUMNS) + "|"]
    for r in rows:
        cells = [_fmt(r.get(c)).replace("|", "\\|").replace("\n", " ") for c in SUMMARY_COLUMNS]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def write_summary(rows, outdir):
    """Write ``summary.csv`` and ``summary.md`` (columns :data:`SUMMARY_COLUMNS`) in ``outdir``.

    Returns
    -------
    (pathlib.Path, pathlib.Path)
        The CSV and markdown paths.
    """
    outdir = Path(outdir)
    buf = _io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=SUMMARY_COLUMNS, extrasaction="ignore",
                            lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    paths = (outdir / "summary.csv", outdir / "summary.md")
    for path, text in zip(paths, (buf.getvalue(), summary_markdown(rows))):
        with atomic_path(path) as tmp:
            tmp.write_text(text, encoding="utf-8")
    return paths

"""Issue #15's acceptance run: ``igl-spheremap MESH -o X.surf.gii`` and ``-o lh.X`` on every mesh.

For each mesh of the folder and each float32 output family (GIfTI ``.surf.gii``,
FreeSurfer ``lh.<mesh>``), runs the command line as a user would (a fresh
process, default options: the float32 precision setting is chosen for these
formats), then checks the written sphere independently of the library: it is
read back with nibabel and its folded faces are counted with numpy's
determinant ``det[X_i, X_j, X_k] <= 0`` on the stored float32 coordinates
(radius 100, centred at the origin, faces as stored).  The table gives the exit
code, what the JSON report says (``folds``, ``folds_stored``, ``success``),
the independent count and the wall time of the command.

Usage::

    python benchmarks/cli_outputs.py                       # ../shared/meshes
    python benchmarks/cli_outputs.py MESH_DIR --out DIR
"""

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import nibabel as nib
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import DEFAULT_OUT, REPO_ROOT, environment, environment_line, write_outputs  # noqa

DEFAULT_MESHES = REPO_ROOT.parent / "shared" / "meshes"
FAMILIES = {"gifti": "{stem}.sphere.surf.gii", "freesurfer": "lh.{stem}_sphere"}


def stored_folds(path, family):
    """Folded faces of the sphere stored in ``path``, counted with numpy alone."""
    if family == "gifti":
        img = nib.load(str(path))
        X, F = img.agg_data("pointset"), img.agg_data("triangle")
    else:
        X, F = nib.freesurfer.read_geometry(str(path))[:2]
    X = np.asarray(X, dtype=np.float64)
    det = np.linalg.det(np.stack([X[F[:, 0]], X[F[:, 1]], X[F[:, 2]]], axis=1))
    return int(np.count_nonzero(det <= 0)), X.dtype


def run_one(mesh, family, folder):
    out = folder / FAMILIES[family].format(stem=mesh.stem)
    report = folder / f"{mesh.stem}_{family}.json"
    cmd = [sys.executable, "-m", "igl_spheremap", str(mesh), "-o", str(out), "--json", str(report),
           "--no-progress", "-q"]
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True)
    seconds = time.perf_counter() - t0
    row = dict(mesh=mesh.stem, family=family, exit_code=proc.returncode, seconds=seconds)
    if report.exists():
        rep = json.loads(report.read_text())
        row.update(folds=rep.get("folds"), folds_stored=rep.get("folds_stored"),
                   success=rep.get("success"), precision=rep.get("options", {}).get("precision"),
                   message=rep.get("message"))
    if out.exists():
        row["folds_numpy"], _ = stored_folds(out, family)
    else:
        row["status"] = f"no output: {proc.stderr.strip()[-200:]}"
    return row


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("mesh_dir", nargs="?", type=Path, default=DEFAULT_MESHES)
    p.add_argument("--out", type=Path, default=DEFAULT_OUT)
    args = p.parse_args(argv)
    env = environment()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for mesh in sorted(args.mesh_dir.glob("*.obj")):
            for family in FAMILIES:
                rows.append(run_one(mesh, family, Path(tmp)))
                r = rows[-1]
                print(f"{r['mesh']:>32} {family:>10}: exit {r['exit_code']}, folds {r.get('folds')}, "
                      f"stored {r.get('folds_stored')}, numpy {r.get('folds_numpy')}, "
                      f"{r['seconds']:.1f} s", flush=True)
    cols = [("mesh", "mesh"), ("family", "output"), ("precision", "precision"),
            ("exit_code", "exit code"), ("folds", "folds (report)"),
            ("folds_stored", "folds stored (report)"), ("folds_numpy", "folds stored (numpy)"),
            ("success", "success"), ("seconds", "seconds")]
    lines = [f"# The command line's float32 outputs (issue #15)\n", environment_line(env) + "\n",
             "| " + " | ".join(h for _, h in cols) + " |",
             "|" + "---|" * len(cols)]
    for r in rows:
        cells = [f"{r.get(k):.1f}" if k == "seconds" else str(r.get(k, "–")) for k, _ in cols]
        lines.append("| " + " | ".join(cells) + " |")
    bad = [r for r in rows if r.get("folds_numpy") != 0 or r["exit_code"] != 0]
    lines.append(f"\n{len(rows) - len(bad)} of {len(rows)} files have 0 folded faces as stored and "
                 f"exit code 0.\n\nCommand: `python benchmarks/cli_outputs.py`; *folds stored (numpy)* "
                 "= faces of the file read back with nibabel whose float32 corners have "
                 "`det <= 0`.\n")
    write_outputs(args.out, "cli_outputs", "\n".join(lines), dict(environment=env, rows=rows))


if __name__ == "__main__":
    main()

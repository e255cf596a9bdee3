"""Damaged input files against the readers: does any crash, hang or raise a surprise?

A small icosphere is written in every format ``read_mesh`` reads (OBJ, OFF, ASCII
and binary PLY, ASCII and binary STL, VRML, MEDIT ``.mesh``, ASCII and binary Gmsh
``.msh``, GIfTI, FreeSurfer), a per-vertex function in every format
``read_vertex_data`` reads (``.npy``, ``.npz``, ``.txt``, ``.csv``, ``.func.gii``,
FreeSurfer ``lh.*.curv``), four landmark indices as ``read_landmarks`` reads them and
a map's result file (``save_result`` / ``load_result``), FreeSurfer overlays (``.mgh``,
``.mgz``) read as data, labels (``.annot``, ``.label.gii``) as ``read_vertex_labels``
reads them and a ``.label`` vertex list as ``read_vertex_mask`` reads it,
and each file is damaged in three ways, with a fixed seed: cut at 40 points, one byte
replaced at 60 random places (by digits, signs, ``nan``, control bytes, ...) and one
line deleted, repeated or cut in half at 30 random places.  Every damaged file is read
by its reader in a worker process, twice (in two workers); a file that kills the worker
(``crash``) or takes longer than ``--timeout`` seconds (``hang``) is recorded and a new
worker goes on, and one whose two readings end otherwise is ``unstable`` (uninitialised
memory in a reader).

Outcomes: ``read`` (arrays returned: a damage that leaves a valid file, or changed
numbers no reader can tell), ``refused`` (ValueError or OSError: the message is the
user's), ``other`` (any other exception: a bug), ``crash``, ``hang``.

    python benchmarks/reader_fuzz.py                 # about 6 minutes
    python benchmarks/reader_fuzz.py --formats wrl stl --out /tmp/fuzz
"""

import argparse
import random
import re
import select
import subprocess
import sys
import tempfile
from pathlib import Path

import harness

FORMATS = ("obj", "off", "ply", "ply_binary", "stl", "stl_binary", "wrl", "mesh", "msh",
           "msh_binary", "surf.gii", "freesurfer", "npy", "npz", "txt", "csv", "func.gii", "curv",
           "landmarks", "result", "mgh", "mgz", "annot", "label.gii", "label")

#: The reader of each format that is not a mesh: per-vertex data, landmark vertex indices.
READER = dict.fromkeys(("npy", "npz", "txt", "csv", "func.gii", "curv"), "data")
READER.update(landmarks="landmarks", result="result", mgh="data", mgz="data", annot="labels")
READER.update({"label.gii": "labels", "label": "mask"})
SUFFIX = {"ply_binary": ".ply", "stl_binary": ".stl", "msh_binary": ".msh", "surf.gii": ".surf.gii"}
SUFFIX.update({fmt: "." + fmt for fmt in ("obj", "off", "ply", "stl", "wrl", "mesh", "msh", "npy",
                                          "npz", "txt", "csv", "func.gii")})
SUFFIX.update(landmarks=".txt", result=".npz", mgh=".mgh", mgz=".mgz", annot=".annot",
              label=".label")
SUFFIX["label.gii"] = ".label.gii"
REPLACEMENTS = [b"0", b"9", b"-", b"e", b".", b"\x00", b"\r", b" ", b"\n", b"x", b"#", b"/",
                b"\xff", b"nan", b"1e999", b"-1", b"99999"]
WORKER = """
import sys, warnings
warnings.simplefilter("ignore")
from igl_spheremap import icosphere
from igl_spheremap.io import (load_result, read_landmarks, read_mesh, read_vertex_data,
                              read_vertex_labels, read_vertex_mask)
V0, F0 = icosphere(int(sys.argv[1]))
for line in sys.stdin:
    reader, path = line.rstrip("\\n").split("\\t")
    print("@@begin", path, flush=True)
    try:
        if reader == "mesh":
            V, F, _ = read_mesh(path)
            print("@@read", V.shape[0], F.shape[0], flush=True)
        elif reader == "data":
            print("@@read", read_vertex_data(path, len(V0))[0].shape, flush=True)
        elif reader == "labels":
            print("@@read", read_vertex_labels(path, len(V0))[0].shape, flush=True)
        elif reader == "mask":
            print("@@read", int(read_vertex_mask(path, len(V0)).sum()), flush=True)
        elif reader == "result":
            print("@@read", load_result(path).U.shape, flush=True)
        else:
            print("@@read", read_landmarks(path, V0, F0).tolist(), flush=True)
    except (ValueError, OSError) as exc:
        print("@@refused", type(exc).__name__, str(exc).replace(chr(10), " ")[:300], flush=True)
    except Exception as exc:
        print("@@other", type(exc).__name__, str(exc).replace(chr(10), " ")[:300], flush=True)
"""


def base_files(folder, level=1):
    """The undamaged icosphere (``level`` 1: 42 vertices, 80 faces) in every format and a
    function and landmarks on it: {format: path}."""
    import igl
    import nibabel as nib
    import numpy as np
    from nibabel.gifti import GiftiDataArray, GiftiImage
    from plyfile import PlyData, PlyElement

    from igl_spheremap import icosphere, spherical_conformal_map
    from igl_spheremap.io import save_result

    V, F = icosphere(level)
    out = {}
    for fmt in ("obj", "off", "wrl", "mesh"):
        out[fmt] = folder / f"base.{fmt}"
        igl.write_triangle_mesh(str(out[fmt]), V, F)
    for fmt, binary in (("stl", False), ("stl_binary", True)):
        out[fmt] = folder / f"{fmt}.stl"
        igl.writeSTL(str(out[fmt]), V, F, binary)
    out["msh_binary"] = folder / "binary.msh"
    igl.writeMSH(str(out["msh_binary"]), V, F, np.zeros((0, 4), np.int64),
                 np.ones(len(F), np.int64), np.zeros(0, np.int64))
    out["msh"] = folder / "ascii.msh"  # Gmsh 2.2 ASCII: nodes, then 3-node triangles (type 2)
    out["msh"].write_text(
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n" + f"{len(V)}\n"
        + "".join(f"{i + 1} {x:.17g} {y:.17g} {z:.17g}\n" for i, (x, y, z) in enumerate(V))
        + "$EndNodes\n$Elements\n" + f"{len(F)}\n"
        + "".join(f"{k + 1} 2 2 1 1 {a + 1} {b + 1} {c + 1}\n" for k, (a, b, c) in enumerate(F))
        + "$EndElements\n")
    vertex = np.array([tuple(v) for v in V], dtype=[("x", "f8"), ("y", "f8"), ("z", "f8")])
    face = np.array([(list(f),) for f in F], dtype=[("vertex_indices", "i4", (3,))])
    for fmt, text in (("ply", True), ("ply_binary", False)):
        out[fmt] = folder / f"{fmt}.ply"
        PlyData([PlyElement.describe(vertex, "vertex"), PlyElement.describe(face, "face")],
                text=text).write(str(out[fmt]))
    x = np.linspace(-1.0, 1.0, len(V))
    for fmt in ("npy", "npz", "txt", "csv", "func.gii", "curv", "landmarks"):
        out[fmt] = folder / ("lh.base" + "." + fmt if fmt == "curv" else f"base_{fmt}{SUFFIX[fmt]}")
    np.save(out["npy"], x)
    np.savez(out["npz"], a=x, b=2 * x)
    np.savetxt(out["txt"], x)
    np.savetxt(out["csv"], np.column_stack([x, x]), delimiter=",")
    nib.save(GiftiImage(darrays=[GiftiDataArray(x.astype(np.float32), intent="NIFTI_INTENT_SHAPE",
                                                datatype="NIFTI_TYPE_FLOAT32")]),
             str(out["func.gii"]))
    nib.freesurfer.write_morph_data(str(out["curv"]), x.astype(np.float32))
    out["landmarks"].write_text("0\n5\n12\n30\n")
    out["result"] = folder / "base_result.npz"
    save_result(out["result"], spherical_conformal_map(V, F))
    out["surf.gii"] = folder / "base.surf.gii"
    nib.save(GiftiImage(darrays=[
        GiftiDataArray(V.astype(np.float32), intent="NIFTI_INTENT_POINTSET",
                       datatype="NIFTI_TYPE_FLOAT32"),
        GiftiDataArray(F.astype(np.int32), intent="NIFTI_INTENT_TRIANGLE",
                       datatype="NIFTI_TYPE_INT32")]), str(out["surf.gii"]))
    out.update(freesurfer_vertex_files(folder, V, x))
    out["freesurfer"] = folder / "lh.base"
    nib.freesurfer.write_geometry(str(out["freesurfer"]), V, F.astype(np.int32))
    return out


def freesurfer_vertex_files(folder, V, x):
    """FreeSurfer's per-vertex files of the icosphere ``V``: the function ``x`` as ``.mgh`` and
    ``.mgz`` overlays, three labels as an ``.annot`` and a ``.label.gii``, every fourth vertex
    as an ASCII ``.label``: {format: path}."""
    import nibabel as nib
    import numpy as np
    from nibabel.gifti import GiftiDataArray, GiftiImage

    out = {}
    for fmt in ("mgh", "mgz"):
        out[fmt] = folder / f"lh.base{SUFFIX[fmt]}"
        nib.save(nib.MGHImage(x.astype(np.float32).reshape(-1, 1, 1), np.eye(4)), str(out[fmt]))
    labels = (np.arange(len(V)) % 3).astype(np.int32)
    ctab = np.array([[25, 5, 25, 0, 0], [25, 100, 40, 0, 0], [125, 100, 160, 0, 0]], np.int32)
    out["annot"] = folder / "lh.base.annot"
    nib.freesurfer.write_annot(str(out["annot"]), labels, ctab, [b"unknown", b"a", b"b"],
                               fill_ctab=True)
    out["label.gii"] = folder / "base.label.gii"
    table = nib.gifti.GiftiLabelTable()
    for key, name in enumerate(("unknown", "a", "b")):
        label = nib.gifti.GiftiLabel(key, 0.1 * key, 0.2, 0.3, 1.0)
        label.label = name
        table.labels.append(label)
    nib.save(GiftiImage(darrays=[GiftiDataArray(labels, intent="NIFTI_INTENT_LABEL",
                                                datatype="NIFTI_TYPE_INT32")],
                        labeltable=table), str(out["label.gii"]))
    out["label"] = folder / "lh.base.label"
    picked = np.arange(0, len(V), 4)
    out["label"].write_text(f"#!ascii label , from subject base\n{picked.size}\n" + "".join(
        f"{i} {V[i, 0]:.3f} {V[i, 1]:.3f} {V[i, 2]:.3f} 0.000000\n" for i in picked))
    return out


def damaged(data, rng):
    """``[(description, bytes)]``: 40 cuts, 60 replaced bytes, 30 line edits of ``data``."""
    out = [(f"cut at byte {int(len(data) * (k + 0.5) / 40)}",
            data[:int(len(data) * (k + 0.5) / 40)]) for k in range(40)]
    for _ in range(60):
        pos, new = rng.randrange(len(data)), rng.choice(REPLACEMENTS)
        out.append((f"byte {pos} replaced by {new!r}", data[:pos] + new + data[pos + 1:]))
    lines = data.split(b"\n")
    for k in range(30):
        edited, i = list(lines), rng.randrange(len(lines))
        kind = ("deleted", "repeated", "cut in half")[k % 3]
        if kind == "deleted":
            del edited[i]
        elif kind == "repeated":
            edited.insert(i, edited[i])
        else:
            edited[i] = edited[i][:len(edited[i]) // 2]
        out.append((f"line {i + 1} {kind}", b"\n".join(edited)))
    return out


def read_all(paths, timeout, level=1):
    """``{path: (outcome, detail)}`` for every path (a dict ``path: reader``), read in worker
    processes by its reader: ``"mesh"`` (``read_mesh``), ``"data"`` (``read_vertex_data`` for
    the icosphere's vertices) or ``"landmarks"`` (``read_landmarks`` on the icosphere)."""
    results, todo = {}, list(paths)
    while todo:
        worker = subprocess.Popen([sys.executable, "-c", WORKER, str(level)],
                                  stdin=subprocess.PIPE,
                                  stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
                                  errors="replace")
        worker.stdin.write("".join(f"{paths[p]}\t{p}\n" for p in todo))
        worker.stdin.close()
        current = None
        while True:
            if not select.select([worker.stdout], [], [], timeout)[0]:
                worker.kill()
                worker.wait()
                results[current] = ("hang", f"no answer in {timeout:g} s")
                break
            line = worker.stdout.readline()
            if not line:  # the worker ended: done, or killed by the file it was reading
                code = worker.wait()
                if current is not None and current not in results:
                    results[current] = ("crash", f"exit code {code}")
                break
            if line.startswith("@@begin "):
                current = line[8:].strip()
            elif line.startswith("@@"):  # libigl prints on stdout too: only ours count
                outcome, _, detail = line[2:].strip().partition(" ")
                results[current] = (outcome, detail)
        todo = [p for p in todo if str(p) not in results]
    return results


def _same(result):
    """A reading's outcome with object addresses blanked (``<ast.Name object at 0x...>``)."""
    return result[0], re.sub(r"0x[0-9a-f]+", "0x", result[1])


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--formats", nargs="+", default=list(FORMATS), choices=FORMATS)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--timeout", type=float, default=20.0)
    parser.add_argument("--level", type=int, default=1,
                        help="subdivisions of the icosphere (1: 42 vertices; 4: 2,562, whose "
                             "text files span several of the OBJ parser's 4,096-line blocks)")
    parser.add_argument("--out", type=Path, default=harness.DEFAULT_OUT)
    args = parser.parse_args(argv)
    args.argv = sys.argv[1:] if argv is None else list(argv)
    env = harness.environment()
    rows, found = [], []
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        bases = base_files(folder, args.level)
        for fmt in args.formats:
            base = bases[fmt]
            cases = {}
            rng = random.Random(f"{args.seed}-{fmt}")  # the same damage whatever else runs
            for k, (what, data) in enumerate(damaged(base.read_bytes(), rng)):
                name = (f"lh.damaged{k}" if fmt == "freesurfer" else f"lh.damaged{k}.curv"
                        if fmt == "curv" else f"lh.damaged{k}{SUFFIX[fmt]}")
                path = folder / fmt.replace(".", "_") / name
                path.parent.mkdir(exist_ok=True)
                path.write_bytes(data)
                cases[str(path)] = what
            readers = dict.fromkeys(cases, READER.get(fmt, "mesh"))
            results = read_all(readers, args.timeout, args.level)
            again = read_all(readers, args.timeout, args.level)
            counts = {o: 0 for o in ("read", "refused", "other", "crash", "hang", "unstable")}
            for path, (outcome, detail) in results.items():
                counts[outcome] += 1
                if _same(again[path]) != _same((outcome, detail)):
                    counts["unstable"] += 1
                    outcome, detail = "unstable", f"{detail}; then {' '.join(again[path])}"
                if outcome in ("other", "crash", "hang", "unstable"):
                    found.append(dict(format=fmt, damage=cases[path], outcome=outcome,
                                      detail=detail))
            rows.append(dict(format=fmt, files=len(cases), **counts))
            print(rows[-1], flush=True)
    columns = [("format", "format", "", "l"), ("files", "files", "", "r"),
               ("read", "read", "", "r"), ("refused", "refused", "", "r"),
               ("other exception", "other", "", "r"), ("crash", "crash", "", "r"),
               ("hang", "hang", "", "r"), ("unstable", "unstable", "", "r")]
    listing = "\n".join(f"- {f['format']}, {f['damage']}: **{f['outcome']}** ({f['detail']})"
                        for f in found) or "None."
    markdown = harness.page(
        "Damaged input files against the readers", env,
        harness.command("reader_fuzz", args),
        harness.markdown_table(rows, columns),
        "*read*: arrays returned; *refused*: ValueError or OSError; *other exception*: any "
        "other exception; *crash*: the worker process died; *hang*: no answer in "
        f"{args.timeout:g} s; *unstable*: a second reading, in another worker, ended "
        f"otherwise.\n\nCrashes, hangs, other exceptions and unstable readings:\n\n{listing}")
    harness.write_outputs(args.out, "reader_fuzz", markdown,
                          dict(env=env, rows=rows, found=found, seed=args.seed))
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())

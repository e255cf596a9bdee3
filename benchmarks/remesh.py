"""A shape at another size: refined by libigl subdivision, decimated to an exact vertex count.

:func:`make_mesh` is how ``scaling.py`` makes its sizes and ``registration.py`` its second
triangulation of a surface; :func:`cached_mesh` keeps the results as ``.npz`` files
(:data:`DEFAULT_CACHE`), since the 1M-vertex mesh takes ~30 s and ~2 GB to make.  The
choice of subdivision and decimation is explained in ``scaling.py``'s docstring.
"""

import hashlib
import tempfile
import time
from pathlib import Path

import numpy as np

from harness import mesh_name

DEFAULT_CACHE = Path(tempfile.gettempdir()) / "igl_spheremap_scaling_cache"


def make_mesh(V, F, n_target, subdivision="loop", decimation="decimate"):
    """The shape ``(V, F)`` refined and decimated to ``n_target`` vertices.

    Subdivide (``igl.loop`` or ``igl.upsample``) the fewest times that reach at least
    ``n_target`` vertices (``n -> 4n - 6`` per pass on a closed genus-0 mesh), then
    collapse edges (``igl.decimate`` or ``igl.qslim``) down to ``2 n_target - 4`` faces
    (a closed genus-0 mesh with ``N`` vertices has ``2N - 4`` faces).

    Returns
    -------
    V : (N, 3) float64 array
    F : (2N - 4, 3) int64 array
    made_by : str
        How the mesh was made, e.g. ``"loop x2, decimate"``.

    Raises
    ------
    RuntimeError
        If decimation fails or does not return a closed genus-0 mesh.
    """
    import igl
    V = np.ascontiguousarray(V, dtype=np.float64)
    F = np.ascontiguousarray(F, dtype=np.int64)
    subdivide = {"loop": igl.loop, "upsample": igl.upsample}[subdivision]
    k = 0
    while V.shape[0] < n_target:
        V, F = subdivide(V, F, 1)
        k += 1
    made = [f"{subdivision} x{k}"] if k else []
    if V.shape[0] > n_target:
        collapse = {"qslim": igl.qslim, "decimate": igl.decimate}[decimation]
        out = collapse(np.asfortranarray(V), np.asfortranarray(F.astype(np.int32)),
                       2 * n_target - 4)
        if isinstance(out[0], (bool, np.bool_)):  # older bindings return a success flag first
            if not out[0]:
                raise RuntimeError(f"igl.{decimation} failed at {n_target} vertices")
            out = out[1:]
        V = np.ascontiguousarray(out[0], dtype=np.float64)
        F = np.ascontiguousarray(out[1], dtype=np.int64)
        made.append(decimation)
    E = igl.edges(F)
    if V.shape[0] - E.shape[0] + F.shape[0] != 2 or np.unique(F).size != V.shape[0]:
        raise RuntimeError(f"refined/decimated mesh at {n_target} vertices is not closed "
                           f"genus 0 (V={V.shape[0]}, E={E.shape[0]}, F={F.shape[0]})")
    return V, F, ", ".join(made) or "original"


def cached_mesh(mesh_path, V0, F0, n, subdivision, decimation, cache_dir):
    """:func:`make_mesh` through a cache of ``.npz`` files.

    The file name holds the shape's name, the first 12 hex digits of the SHA-1 of the
    shape file, ``n`` and the two methods, so a changed input or method makes a new
    file.  ``cache_dir=None`` disables the cache.

    Returns
    -------
    path : pathlib.Path or None
        The cached ``.npz`` (arrays ``V``, ``F``, ``made_by``), None without cache.
    V, F, made_by, seconds
        As :func:`make_mesh`; ``seconds`` is the time it took to generate the mesh
        (recorded in the cache file).
    """
    path = None
    if cache_dir is not None:
        digest = hashlib.sha1(Path(mesh_path).read_bytes()).hexdigest()[:12]
        path = (Path(cache_dir) / f"{mesh_name(mesh_path)}_{digest}_{n}_{subdivision}_"
                f"{decimation}.npz")
        if path.exists():
            with np.load(path) as data:
                return (path, np.ascontiguousarray(data["V"], dtype=np.float64),
                        np.ascontiguousarray(data["F"], dtype=np.int64), str(data["made_by"]),
                        float(data["seconds"]))
    t0 = time.perf_counter()
    V, F, made_by = make_mesh(V0, F0, n, subdivision, decimation)
    seconds = time.perf_counter() - t0
    if path is not None:
        save_npz(path, V=V, F=F, made_by=np.array(made_by), seconds=np.array(seconds))
    return path, V, F, made_by, seconds


def save_npz(path, **arrays):
    """``numpy.savez`` to ``path`` through a temporary file (a reader never sees half a file)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.stem}.tmp.npz")
    np.savez(tmp, **arrays)
    tmp.replace(path)

"""Read a landmark list: vertex indices, or points snapped to the surface's nearest vertices."""

from pathlib import Path

import igl
import numpy as np

from ..errors import plural


def read_landmarks(path, V, F, *, return_distances=False):
    """Landmark vertices from a text file: one vertex index per line, or ``x y z`` rows.

    Rows of one integer are 0-based vertex indices.  Rows of three numbers are
    points, each snapped to the nearest vertex of ``V`` (Euclidean); a point
    farther from that vertex than the longest edge at the vertex is not on the
    surface near it (a point anywhere on the faces around a vertex is closer than
    that) and is refused.  Blank lines and text after ``#`` are skipped; commas
    count as spaces; a UTF-8 byte-order mark is ignored.

    Parameters
    ----------
    path : str or os.PathLike
    V : (n, 3) float64 array
        The surface's vertices.
    F : (m, 3) int array
        Its faces (the edge lengths of the snapping tolerance).
    return_distances : bool
        Also return each landmark's snapping distance.

    Returns
    -------
    lm : (k,) int64 array
    distances : (k,) float64 array
        Only with ``return_distances``: distance from each ``x y z`` row to its
        vertex, in the units of ``V`` (0 for index rows).

    Raises
    ------
    FileNotFoundError
        ``path`` does not exist.
    ValueError
        A binary file; a file that lists no landmark (blank or comment lines
        only); rows that are neither one integer nor three numbers (count and
        first line given); indices outside ``0..n-1``; points
        farther from their nearest vertex than the longest edge there (count,
        first line, distance and tolerance given).
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no such landmark file: '{path}'")
    raw = path.read_bytes()
    if b"\0" in raw:
        raise ValueError(f"'{path}' is a binary file, not a text list of landmarks (one vertex "
                         "index or 'x y z' per line)")
    rows, lines, bad = _rows(raw.decode("utf-8-sig", errors="replace"))
    if bad:
        are = "is" if len(bad) == 1 else "are"
        raise ValueError(f"{plural(len(bad), 'line')} of '{path}' {are} neither a vertex index "
                         f"nor 'x y z' (first: line {bad[0]})")
    if not rows:
        raise ValueError(f"'{path}' lists no landmarks (every line is blank or a comment); for "
                         "a map without landmarks leave the landmark files out")
    lm, dist = _snapped(rows, np.asarray(V, dtype=np.float64))
    out = (lm < 0) | (lm >= len(V))
    if out.any():
        first = lines[int(np.flatnonzero(out)[0])]
        raise ValueError(f"{plural(int(out.sum()), 'landmark index', 'landmark indices')} in "
                         f"'{path}' outside 0..{len(V) - 1} "
                         f"(first: line {first})")
    _check_snapping(path, lines, lm, dist, V, F)
    return (lm, dist) if return_distances else lm


def _rows(text):
    """``(index, point)`` per landmark row, the line numbers, and the bad line numbers."""
    rows, lines, bad = [], [], []
    for i, line in enumerate(text.splitlines(), start=1):
        words = line.split("#", 1)[0].replace(",", " ").split()
        if not words:
            continue
        try:
            values = [float(t) for t in words]
        except ValueError:
            values = []
        if len(values) == 1 and float(values[0]).is_integer():
            # beyond int64 ('1e30'): out of range all the same, reported as such
            rows.append((int(values[0]) if abs(values[0]) < 2.0 ** 62 else -1, None))
        elif len(values) == 3 and np.all(np.isfinite(values)):
            rows.append((None, values))
        else:
            bad.append(i)
            continue
        lines.append(i)
    return rows, lines, bad


def _snapped(rows, V):
    """Vertex per row (points snapped to the nearest vertex) and the snapping distances."""
    from scipy.spatial import cKDTree

    lm = np.array([i if i is not None else -1 for i, _ in rows], dtype=np.int64)
    dist = np.zeros(len(rows))
    is_point = np.array([p is not None for _, p in rows], dtype=bool)
    if is_point.any():
        d, nearest = cKDTree(V).query(np.array([p for _, p in rows if p is not None]))
        lm[is_point], dist[is_point] = nearest, d
    return lm, dist


def _check_snapping(path, lines, lm, dist, V, F):
    """Refuse points farther from their vertex than the longest edge at that vertex."""
    E = igl.edges(np.asarray(F, dtype=np.int64))
    length = np.linalg.norm(V[E[:, 0]] - V[E[:, 1]], axis=1)
    longest = np.zeros(len(V))
    np.maximum.at(longest, E[:, 0], length)
    np.maximum.at(longest, E[:, 1], length)
    far = dist > longest[lm]
    if far.any():
        k, count = int(np.flatnonzero(far)[0]), int(far.sum())
        rows = plural(count, "'x y z' row")
        are, their = ("is", "its") if count == 1 else ("are", "their")
        raise ValueError(f"{rows} of '{path}' {are} not on the surface: farther from {their} "
                         f"nearest vertex than the longest edge there (first: line {lines[k]}, "
                         f"{dist[k]:.4g} from vertex {lm[k]}, tolerance {longest[lm[k]]:.4g})")

"""Strict check of an OBJ file's vertex and face lines, before libigl reads it."""

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import plural
from .line_scan import BAD, INTEGER, WHITESPACE, Chunk, Lines, first_of

#: Longest line libigl's OBJ reader takes whole: it reads with ``fgets`` into a
#: 2048-byte buffer, so a longer line is cut and its rest read as a new line.
LIBIGL_LINE_MAX = 2046

_SLASH_SUFFIX = re.compile(rb"(?<=[^\s/])/\S*")  # "12/5/7" -> "12", keeps a leading "/5"


@dataclass(frozen=True)
class TextMesh:
    """What a strict parse of a text mesh file found.

    Attributes
    ----------
    V : (n, 3) float64 array
        Vertex positions, one row per vertex line, in file order.
    F : (m, 3) int64 array
        Triangles, 0-based; a polygon ``(i0, i1, ..., ik)`` is split into the fan
        ``(i0, ij, ij+1)``, as libigl's ``read_triangle_mesh`` does.
    polygons : int
        Number of faces with more than 3 vertices (split into the fan above).
    """

    V: np.ndarray
    F: np.ndarray
    polygons: int


def check_obj(path, data=None):
    """Parse the ``v`` and ``f`` lines of an OBJ file strictly; raise on what libigl would misread.

    libigl's OBJ reader (2.6.3) silently truncates a face index such as
    ``164.5`` or ``3x`` to ``164`` / ``3``, accepts indices 0 or beyond the
    vertex count, drops faces with fewer than 3 vertices, reads ``1.2.3`` as
    two coordinates, and reports ``nan`` / ``inf`` coordinates or indented
    lines as "should have at least 3 coordinates".  This check finds all of
    these first, with a count and the first line of each.

    Accepted: ``v x y z [w ...]`` (extra numbers ignored), faces ``f i j k ...``
    with ``i``, ``i/t``, ``i//n``, ``i/t/n`` elements, 1-based indices or
    negative indices relative to the vertices defined so far (``-1`` is the
    last one), polygons (split into a fan, as libigl does), comments and other
    statements (``vt``, ``vn``, ``g``, ``usemtl`` ...), which are skipped.

    Parameters
    ----------
    path : str or os.PathLike
        The file (also named in messages).
    data : bytes, optional
        Its content, when already read.

    Returns
    -------
    TextMesh
        The vertices and triangles the file describes.

    Raises
    ------
    ValueError
        Listing every kind of problem found, each with its count and first
        line: vertex lines with fewer than 3 coordinates, non-numeric
        coordinates, non-finite coordinates (``nan``, ``inf``, overflow),
        faces with fewer than 3 vertices, face indices that are not integers,
        face indices out of range (0, beyond the vertex count, or relative
        indices reaching before the first vertex), ``v``/``f`` lines with
        leading whitespace or longer than libigl's line buffer, line
        continuations (``\\``), files without vertex or face lines, and
        control bytes (a binary file).
    """
    data = Path(path).read_bytes() if data is None else data
    lines = Lines(data)
    refuse_binary(path, lines, "OBJ")
    sep = WHITESPACE[lines.byte(1)]
    is_v = (lines.byte(0) == ord("v")) & sep
    is_f = (lines.byte(0) == ord("f")) & sep
    problems = _layout_problems(lines, is_v, is_f)
    V, vertex_problems = _vertices(lines, is_v)
    F, polygons, face_problems = _faces(lines, is_v, is_f)
    problems += vertex_problems + face_problems
    if not is_v.any() or not is_f.any():
        problems.append(f"no triangles: {plural(int(is_v.sum()), 'vertex line')} ('v x y z') and "
                        f"{plural(int(is_f.sum()), 'face line')} ('f i j k')")
    if problems:
        raise ValueError(f"'{path}' is not a valid OBJ triangle mesh: " + "; ".join(problems))
    return TextMesh(V, F, polygons)


def refuse_binary(path, lines, name):
    """Raise when the file holds control bytes: binary content, not a text mesh."""
    found = first_of(lines.control_bytes(), lines, "lines with control bytes")
    if found:
        raise ValueError(f"'{path}' is not a text {name} file (binary content?): {found}")


def _layout_problems(lines, is_v, is_f):
    """Indented ``v``/``f`` lines, over-long lines, continuation lines."""
    first = lines.first_token_start()
    buf = lines.buf
    indented = np.flatnonzero((first > lines.starts) & (first < lines.ends)
                              & np.isin(buf[first], (ord("v"), ord("f")))
                              & WHITESPACE[buf[np.minimum(first + 1, len(buf) - 1)]])
    too_long = np.flatnonzero((lines.ends - lines.starts > LIBIGL_LINE_MAX) & (is_v | is_f))
    last = np.maximum(lines.ends - 1, 0)
    last = np.where((buf[last] == 13) & (last > lines.starts), last - 1, last)
    continued = np.flatnonzero((buf[last] == ord("\\")) & (lines.ends > lines.starts))
    found = [first_of(indented, lines, "'v'/'f' lines with leading whitespace, which libigl's "
                      "reader cannot parse"),
             first_of(too_long, lines, f"'v'/'f' lines longer than {LIBIGL_LINE_MAX} characters, "
                      "which libigl's reader cuts"),
             first_of(continued, lines, "lines continued with '\\', which libigl's reader "
                      "does not join")]
    return [p for p in found if p]


def _vertices(lines, is_v):
    """(n, 3) coordinates of the vertex lines and the problems found in them."""
    chunk = lines.chunk(is_v, skip=np.ones(len(is_v), dtype=np.int64))
    values, status = chunk.numbers("float")
    token_line = chunk.token_line()
    first = np.cumsum(chunk.counts) - chunk.counts
    has3 = chunk.counts >= 3
    V = np.full((len(chunk.counts), 3), np.nan)
    V[has3] = values[first[has3, None] + np.arange(3)]
    bad_tokens = np.flatnonzero(status == BAD)
    bad_rows = np.zeros(len(V), dtype=bool)
    bad_rows[token_line[bad_tokens]] = True
    nonfinite = has3 & ~bad_rows & ~np.isfinite(V).all(axis=1)
    found = [first_of(chunk.lines[~has3], lines, "vertex lines with fewer than 3 coordinates"),
             _tokens_message(bad_tokens, token_line, chunk, lines,
                             "non-numeric vertex coordinates"),
             first_of(chunk.lines[nonfinite], lines,
                      "vertices with non-finite coordinates (nan, inf or overflow)")]
    return V, [p for p in found if p]


def _faces(lines, is_v, is_f):
    """Triangles (fan-split polygons), polygon count and the problems of the face lines."""
    chunk = lines.chunk(is_f, skip=np.ones(len(is_f), dtype=np.int64))
    text = chunk.buf.tobytes()
    if b"/" in text:  # keep the vertex index of "i/t/n" elements
        buf = np.frombuffer(_SLASH_SUFFIX.sub(b"", text), dtype=np.uint8)
        ends = np.flatnonzero(buf == 10)
        offsets = np.concatenate((ends[:0], [0], ends[:-1] + 1))[:len(ends)].astype(np.int64)
        chunk = Chunk(buf, offsets, chunk.lines)
    values, status = chunk.numbers("int")
    token_line = chunk.token_line()
    n = int(is_v.sum())
    before = np.cumsum(is_v)[chunk.lines][token_line]  # vertices defined before each face line
    index = np.where(values > 0, values - 1, before + values)
    out = (status == INTEGER) & ((values == 0) | (index < 0) | (index >= n))
    bad = np.flatnonzero(status != INTEGER)
    found = [first_of(chunk.lines[chunk.counts < 3], lines, "faces with fewer than 3 vertices"),
             _tokens_message(bad, token_line, chunk, lines, "face indices that are not integers"),
             _tokens_message(np.flatnonzero(out), token_line, chunk, lines,
                             f"face indices out of range (valid: 1 to {n}, or -1 back to the "
                             "first vertex defined before the face)")]
    F = fan_triangles(np.where(status == INTEGER, index, -1).astype(np.int64), chunk.counts)
    return F, int(np.count_nonzero(chunk.counts > 3)), [p for p in found if p]


def _tokens_message(tokens, token_line, chunk, lines, what):
    """``"<what>: N (first on line K: ...)"`` for flagged tokens."""
    if len(tokens) == 0:
        return None
    first = int(chunk.lines[token_line[tokens]].min())
    return f"{what}: {len(tokens)} (first on line {first + 1}: '{lines.text(first)}')"


def fan_triangles(index, counts):
    """Split faces of ``counts`` vertices (flat ``index``) into fans ``(i0, ij, ij+1)``.

    Faces with fewer than 3 vertices give no triangle.

    Parameters
    ----------
    index : (sum(counts),) int64 array
    counts : (k,) int64 array

    Returns
    -------
    (m, 3) int64 array
        ``m = sum(max(counts - 2, 0))``.
    """
    if np.all(counts == 3):
        return index.reshape(-1, 3)
    first = np.cumsum(counts) - counts
    ntri = np.maximum(counts - 2, 0)
    face = np.repeat(np.arange(len(counts)), ntri)
    j = np.arange(ntri.sum()) - np.repeat(np.cumsum(ntri) - ntri, ntri)
    base = first[face]
    return np.stack([index[base], index[base + j + 1], index[base + j + 2]], axis=1)

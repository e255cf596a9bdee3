"""Strict check of an OFF file (header counts, vertex and face lines), before libigl reads it."""

from pathlib import Path

import numpy as np

from ..errors import plural
from .line_scan import BAD, INTEGER, Lines, first_of
from .check_obj import TextMesh, refuse_binary, fan_triangles

#: Keywords libigl's OFF reader accepts on the first line.
OFF_KEYWORDS = (b"OFF", b"COFF", b"NOFF")


def check_off(path, data=None):
    """Parse an OFF file strictly; raise on anything libigl would misread or crash on.

    libigl's OFF reader (2.6.3) crashes the process (segmentation fault) when
    the header announces fewer vertices than the file has, silently drops the
    faces beyond the header's count, accepts ``nan`` coordinates, indices
    beyond the vertex count or negative, and drops faces of fewer than 3
    vertices.  This check reads the layout libigl expects, one element per
    line: a first line ``OFF`` / ``COFF`` / ``NOFF`` (the counts may follow on
    it), a line ``nv nf [ne]``, ``nv`` vertex lines ``x y z [...]`` and ``nf``
    face lines ``k i1 ... ik [color ...]`` with 0-based indices.  Blank lines
    and ``#`` comments are skipped.

    Parameters
    ----------
    path : str or os.PathLike
        The file (also named in messages).
    data : bytes, optional
        Its content, when already read.

    Returns
    -------
    TextMesh
        Vertices, triangles (polygons split into fans ``(i0, ij, ij+1)`` as
        libigl does) and the number of polygons.

    Raises
    ------
    ValueError
        Listing every kind of problem found, with counts and first lines: a
        missing or unknown keyword, header counts that are not integers or
        disagree with the number of element lines, vertex lines with fewer
        than 3 coordinates, non-numeric or non-finite coordinates, face lines
        whose vertex count is not an integer of at least 3 or exceeds the
        numbers on the line, non-integer or out-of-range indices, control
        bytes (a binary file).
    """
    data = Path(path).read_bytes() if data is None else data
    lines = Lines(data)
    refuse_binary(path, lines, "OFF")
    first = lines.first_token_start()
    content = np.flatnonzero((first < lines.ends) & (lines.buf[first] != ord("#")))
    header, problems = _header(lines, content)
    if header is None:
        raise ValueError(f"'{path}' is not a valid OFF file: " + "; ".join(problems))
    nv, nf, body = header
    if len(body) != nv + nf:  # the split into vertex and face lines is unknown: stop here
        raise ValueError(f"'{path}' is not a valid OFF file: the header (line {content[0] + 1}) "
                         f"announces {plural(nv, 'vertex', 'vertices')} and {plural(nf, 'face')}, "
                         f"{plural(nv + nf, 'element line')}, but "
                         f"{plural(len(body), 'follows', 'follow')} (blank and '#' lines not "
                         "counted)")
    is_v = np.zeros(len(lines.starts), dtype=bool)
    is_v[body[:nv]] = True
    is_f = np.zeros(len(lines.starts), dtype=bool)
    is_f[body[nv:nv + nf]] = True
    V, vertex_problems = _vertices(lines, is_v)
    F, polygons, face_problems = _faces(lines, is_f, nv)
    problems += vertex_problems + face_problems
    if nv == 0 or nf == 0:
        problems.append(f"no triangles: the header announces {plural(nv, 'vertex', 'vertices')} "
                        f"and {plural(nf, 'face')}")
    if problems:
        raise ValueError(f"'{path}' is not a valid OFF triangle mesh: " + "; ".join(problems))
    return TextMesh(V, F, polygons)


def _header(lines, content):
    """``(nv, nf, element line indices)`` or None, and the problems found."""
    if len(content) == 0:
        return None, ["no content (only blank or comment lines)"]
    tokens = _line_bytes(lines, content[0]).split()
    if tokens[0] not in OFF_KEYWORDS:
        return None, [f"the first line must be OFF, COFF or NOFF, not '{lines.text(content[0])}'"]
    if len(tokens) >= 3:
        counts, body = tokens[1:], content[1:]
    elif len(content) > 1:
        counts, body = _line_bytes(lines, content[1]).split(), content[2:]
    else:
        counts, body = [], content[1:]
    try:
        nv, nf = int(counts[0]), int(counts[1])
        if nv < 0 or nf < 0:
            raise ValueError
    except (IndexError, ValueError):
        where = content[0] if len(tokens) >= 3 or len(content) < 2 else content[1]
        return None, [f"the counts line (line {where + 1}: '{lines.text(where)}') must hold the "
                      "numbers of vertices and faces as non-negative integers"]
    return (nv, nf, body), []


def _line_bytes(lines, i):
    return lines.buf[lines.starts[i]:lines.ends[i]].tobytes()


def _vertices(lines, is_v):
    chunk = lines.chunk(is_v)
    values, status = chunk.numbers("float")
    token_line = chunk.token_line()
    first = np.cumsum(chunk.counts) - chunk.counts
    has3 = chunk.counts >= 3
    V = np.full((len(chunk.counts), 3), np.nan)
    V[has3] = values[first[has3, None] + np.arange(3)]
    bad_rows = np.zeros(len(V), dtype=bool)
    bad_rows[token_line[status == BAD]] = True
    nonfinite = has3 & ~bad_rows & ~np.isfinite(V).all(axis=1)
    found = [first_of(chunk.lines[~has3], lines, "vertex lines with fewer than 3 coordinates"),
             first_of(chunk.lines[bad_rows], lines, "vertex lines with non-numeric values"),
             first_of(chunk.lines[nonfinite], lines,
                      "vertices with non-finite coordinates (nan, inf or overflow)")]
    return V, [p for p in found if p]


def _faces(lines, is_f, nv):
    chunk = lines.chunk(is_f)
    values, status = chunk.numbers("int")
    first = np.cumsum(chunk.counts) - chunk.counts
    has_k = chunk.counts > 0
    k = np.zeros(len(first), dtype=np.int64)
    k_ok = has_k & (status[first * has_k] == INTEGER)
    k[k_ok] = values[first[k_ok]].astype(np.int64)
    short = k_ok & (chunk.counts < k + 1)
    usable = k_ok & ~short & (k >= 3)
    # the k indices after the count, of usable lines
    kk = np.where(usable, k, 0)
    pos = np.repeat(first + 1, kk) + (np.arange(kk.sum()) - np.repeat(np.cumsum(kk) - kk, kk))
    owner = np.repeat(np.arange(len(k)), kk)
    not_int = np.zeros(len(k), dtype=bool)
    not_int[owner[status[pos] != INTEGER]] = True
    out = np.zeros(len(k), dtype=bool)
    index = values[pos]
    out[owner[(status[pos] == INTEGER) & ((index < 0) | (index >= nv))]] = True
    found = [first_of(chunk.lines[~k_ok], lines,
                      "face lines not starting with an integer vertex count"),
             first_of(chunk.lines[k_ok & (k < 3)], lines, "faces with fewer than 3 vertices"),
             first_of(chunk.lines[short], lines, "face lines with fewer indices than their count"),
             first_of(chunk.lines[not_int], lines, "faces with indices that are not integers"),
             first_of(chunk.lines[out], lines,
                      f"faces with indices out of range (valid: 0 to {nv - 1})")]
    F = fan_triangles(np.where(status[pos] == INTEGER, index, -1).astype(np.int64), kk)
    return F, int(np.count_nonzero(usable & (k > 3))), [p for p in found if p]

"""Strict check of a VRML (``.wrl``) file in the layout libigl reads, before libigl reads it."""

import re
from pathlib import Path

import numpy as np

from ..errors import plural
from .check_obj import TextMesh, fan_triangles, refuse_binary
from .line_scan import BLANKS, SCANF_NUMBER, Lines

#: libigl's VRML reader looks for its two keywords with ``fgets`` into a buffer of this
#: many bytes: a longer line is searched in pieces.
LIBIGL_WRL_LINE_MAX = 998

#: Largest number of digits of a face index (``fscanf("%d")`` overflows beyond int32).
INDEX_DIGITS = 9

_INDEX = re.compile(BLANKS + rb"([+-]?\d+),?")
_BLANKS = re.compile(BLANKS)
_POINT = re.compile(rb"point \[")
_NODE = re.compile(rb"([A-Za-z_][\w-]*)\s*\{\s*$")


def check_wrl(path, data=None):
    """Parse a VRML file as libigl's reader does; raise on what it would misread, hang or crash on.

    libigl's VRML reader (2.6.3) reads the first ``IndexedFaceSet`` of a file: it
    skips lines up to one holding ``point [``, reads coordinates as ``x y z`` triples
    (each optionally followed by a comma) until something that is not a number,
    skips lines up to one holding ``coordIndex [`` and reads faces as vertex indices
    ended by a negative number.  It never returns when the second keyword is missing
    (a file cut in its coordinates), aborts the process (``malloc(): invalid size``) on
    a face of fewer than 2 vertices and drops faces of 2, ignores anything on the two
    keyword lines after the keyword, drops a last face without ``-1`` and stops early,
    silently, at a stray token (``1 1 0 ,`` ends the coordinates).  This check follows
    the same reading and refuses each of those, face ends other than ``-1`` (not VRML:
    a lost digit?), a ``TextureCoordinate`` list before the coordinates (libigl would read
    it as the vertices) and a file with more ``point [`` lists (more shapes, which libigl
    would leave out; texture coordinates after the faces are ignored).

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
        The first problem found, with its line: gzip or binary content, a
        missing ``point [`` or ``coordIndex [`` line, values on a keyword line,
        a coordinate triple cut short, a list that stops before its ``]``, faces
        of fewer than 3 vertices (their count), indices below -1 or out of range
        (their count), a last face without ``-1``, no faces, texture coordinates first,
        more shapes.
    """
    data = Path(path).read_bytes() if data is None else data
    if data[:2] == b"\x1f\x8b":
        raise ValueError(f"'{path}' is a gzip-compressed VRML file: decompress it first "
                         "(gunzip), libigl reads plain text only")
    lines = Lines(data)
    refuse_binary(path, lines, "VRML")
    buf = lines.buf.tobytes()

    def line_of(pos):
        return lines.line_at(pos) + 1

    def fail(what, pos):
        k = line_of(pos)
        raise ValueError(f"'{path}' is not a VRML triangle mesh libigl reads: {what} "
                         f"(line {k}: '{lines.text(k - 1)}')")

    first = buf.find(b"point [")
    if first >= 0 and _node(buf, first) == b"TextureCoordinate":
        fail("the first 'point [' list is a TextureCoordinate node, which libigl's reader "
             "would take for the vertices: put the Coordinate node first", first)
    pos = _after_keyword(lines, buf, 0, b"point [", path, fail, line_of)
    V, pos = _points(buf, pos, fail)
    pos = _after_keyword(lines, buf, pos, b"coordIndex [", path, fail, line_of)
    index, counts, pos = _faces(buf, pos, V.shape[0], fail)
    later = [m.start() for m in _POINT.finditer(buf, pos)
             if _node(buf, m.start()) != b"TextureCoordinate"]
    if later:
        lists = plural(len(later), "more 'point [' list")
        fail(f"{lists} (more shapes): libigl reads the first only; "
             "save each shape in its own file", later[0])
    return TextMesh(V, fan_triangles(index, counts), int(np.count_nonzero(counts > 3)))


def _node(buf, at):
    """The VRML node type whose ``{`` opens just before offset ``at`` (bytes; b"" if none)."""
    m = _NODE.search(buf[max(0, at - 200):at])
    return m.group(1) if m else b""


def _after_keyword(lines, buf, pos, keyword, path, fail, line_of):
    """Offset of the line after the first line from ``pos`` holding ``keyword`` (libigl's
    ``fgets`` search, which reads on from there)."""
    found = buf.find(keyword, pos)
    scanned = np.flatnonzero((lines.ends >= pos) & (lines.ends - np.maximum(lines.starts, pos)
                                                    > LIBIGL_WRL_LINE_MAX))
    if scanned.size and (found < 0 or lines.starts[scanned[0]] <= found):
        fail(f"a line longer than {LIBIGL_WRL_LINE_MAX} bytes before '{keyword.decode()}', "
             "which libigl's reader searches in pieces", int(lines.starts[scanned[0]]))
    if found < 0:
        where = ("" if pos == 0 else f" after the coordinates (line {line_of(pos)}): a cut "
                 "file? (libigl's reader would never return)")
        raise ValueError(f"'{path}' is not a VRML triangle mesh libigl reads: no "
                         f"'{keyword.decode()}' line{where}")
    end = buf.find(b"\n", found)
    end = len(buf) - 1 if end < 0 else end
    rest = buf[found + len(keyword):end].strip()
    if rest:
        hint = (" (line ends that are a carriage return alone? convert them to '\\n', e.g. "
                "tr '\\r' '\\n')" if b"\r" in rest else "")
        fail(f"values after '{keyword.decode()}' on its own line, which libigl's reader "
             f"skips: start them on the next line{hint}", found)
    return end + 1


def _points(buf, pos, fail):
    """The coordinate triples from ``pos`` as ``fscanf(" %lf %lf %lf,")`` reads them, and the
    offset of the ``]`` that must end them."""
    rows = []
    while True:
        row, at = [], pos
        while len(row) < 3 and (m := SCANF_NUMBER.match(buf, at)):
            row.append(m.group(1))
            at = m.end()
        if len(row) < 3:
            break
        rows.append(row)
        pos = at + (buf[at:at + 1] == b",")
    if row:
        fail(f"coordinate triple {len(rows) + 1} has fewer than 3 numbers", pos)
    pos = _closing_bracket(buf, pos, "point", plural(len(rows), "coordinate triple"), fail)
    V = np.array(rows, dtype=np.float64).reshape(-1, 3)
    bad = np.flatnonzero(~np.isfinite(V).all(axis=1))
    if bad.size:
        fail(f"{plural(bad.size, 'vertex', 'vertices')} with non-finite coordinates (first: "
             f"vertex {bad[0]})", pos)
    return V, pos


def _faces(buf, pos, nv, fail):
    """Face indices from ``pos`` as ``fscanf(" %d,")`` reads them: flat indices, vertex counts
    and the offset after the list."""
    start, values = pos, []
    while True:
        m = _INDEX.match(buf, pos)
        if m is None:
            break
        if len(m.group(1).lstrip(b"+-")) > INDEX_DIGITS:
            fail(f"a face index of more than {INDEX_DIGITS} digits", m.start(1))
        values.append(int(m.group(1)))
        pos = m.end()
    _closing_bracket(buf, pos, "coordIndex", plural(len(values), "index", "indices"), fail)
    values = np.array(values, dtype=np.int64)
    ends = np.flatnonzero(values < 0)
    if values.size and (ends.size == 0 or ends[-1] != values.size - 1):
        fail("the last face is not closed by -1 (libigl's reader drops it)", pos)
    counts = np.diff(np.concatenate(([-1], ends))) - 1
    problems = [(np.count_nonzero(counts < 3), "face", "faces", " of fewer than 3 vertices"),
                (np.count_nonzero(values < -1), "face end", "face ends", " other than -1"),
                (np.count_nonzero(values >= nv), "index", "indices",
                 f" out of range (valid: 0 to {nv - 1})")]
    found = [plural(count, one, many) + what for count, one, many, what in problems if count]
    if ends.size == 0:
        found.append("no faces")
    if found:
        fail("; ".join(found), start)
    return values[values >= 0], counts, pos


def _closing_bracket(buf, pos, name, read, fail):
    """Offset of the ``]`` at ``pos`` (after blanks) that ends a list (``read``: what it held); a
    stray token there is where libigl's reader stops, silently."""
    m = _BLANKS.match(buf, pos)
    if buf[m.end():m.end() + 1] != b"]":
        what = (f"'{buf[m.end():m.end() + 20].decode('utf-8', 'replace').split()[0]}'"
                if buf[m.end():].strip() else "the end of the file")
        fail(f"the '{name}' list stops after {read} at {what}, not at its ']' "
             "(libigl's reader would stop there without a word)", m.end())
    return m.end()

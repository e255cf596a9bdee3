"""Strict check of an ASCII STL file (line ends, facets, vertex lines) before libigl reads it."""

import re
import struct
from pathlib import Path

import numpy as np

from ..errors import plural
from .check_obj import TextMesh, refuse_binary
from .line_scan import BAD, Chunk, Lines, first_of

#: Longest line (bytes before its ``"\\n"``, a ``"\\r"`` included) libigl's ASCII STL reader
#: takes: it reads with ``istream::getline`` into a 256-byte buffer, and a longer line leaves
#: the stream failed but not at its end, so the reader loops forever.
LIBIGL_STL_LINE_MAX = 255

_BARE_CR = re.compile(rb"\r(?!\n)")
_NORMAL = re.compile(rb"(?m)^[ \t]*normal(?=[ \t\r\n])")


def _read_as_binary(data):
    """Whether libigl (2.6.3) reads the STL content ``data`` (bytes) as binary: it does unless
    it starts with ``solid`` and its size is not ``84 + 50`` times the triangle count stored
    in bytes 80 to 83."""
    if not data.startswith(b"solid"):
        return True
    return len(data) >= 84 and len(data) == 84 + 50 * struct.unpack_from("<I", data, 80)[0]


def check_stl(path, data=None):
    """Parse an ASCII STL file strictly; raise on anything libigl would misread or hang on.

    libigl's ASCII STL reader (2.6.3) never returns on a file whose line ends are a
    carriage return alone (classic Mac OS) or that has a line longer than
    :data:`LIBIGL_STL_LINE_MAX` bytes, silently drops facets that share a line, and
    reads a file cut off after any facet as the facets before the cut.  It reads a
    file that starts with ``solid`` as text unless its size is that of a binary STL,
    so a binary file whose header starts with ``solid`` and whose triangle count
    disagrees with its size is read as text too.  This check reads the layout libigl
    expects: a line per keyword, ``facet normal nx ny nz``, exactly three
    ``vertex x y z`` lines, then ``endfacet``, and ``endsolid`` last.

    Parameters
    ----------
    path : str or os.PathLike
        The file (also named in messages).
    data : bytes, optional
        Its content, when already read.

    Returns
    -------
    TextMesh or None
        None for a file libigl reads as binary (its own reader checks the size and
        the coordinates); else the vertices, one per ``vertex`` line in file order,
        and the triangles ``(3 k, 3 k + 1, 3 k + 2)`` (STL stores every corner
        apart; :func:`igl_spheremap.io.read_mesh` merges them).

    Raises
    ------
    ValueError
        Control bytes (a binary file announcing another triangle count), line ends
        that are a carriage return alone, or lines longer than libigl's buffer, each
        alone (the lines cannot be told apart then); else every kind of problem
        found, with counts and first lines: ``facet`` lines without ``normal`` and
        three coordinates, facets without exactly three ``vertex`` lines or without
        ``endfacet``, vertex lines before the first facet, with fewer than 3
        coordinates, non-numeric or non-finite ones, files without facets, and a last
        line other than ``endsolid`` (a cut file).
    """
    data = Path(path).read_bytes() if data is None else data
    if _read_as_binary(data):
        return None
    lines = Lines(data)
    refuse_binary(path, lines, "ASCII STL (or a binary STL whose triangle count disagrees "
                  "with its size)")
    bare = len(_BARE_CR.findall(data))
    if bare:
        ends = plural(bare, "line end is", "line ends are")
        raise ValueError(f"'{path}' is not an ASCII STL file libigl can read: {ends} "
                         "a carriage return alone (classic Mac OS); libigl's reader joins "
                         "such lines and, on a file of more than a few facets, never returns; "
                         "convert them to '\\n' (e.g. tr '\\r' '\\n')")
    too_long = np.flatnonzero(lines.ends - lines.starts > LIBIGL_STL_LINE_MAX)
    if too_long.size:
        raise ValueError(f"'{path}' is not an ASCII STL file libigl can read: " + first_of(
            too_long, lines, f"lines longer than {LIBIGL_STL_LINE_MAX} characters, on which "
            "libigl's reader never returns"))
    first = lines.first_token_start()
    facet, end, vertex = (_starts_with(lines, first, word)
                          for word in (b"facet", b"endfacet", b"vertex"))
    V, problems = _vertices(lines, first, vertex)
    problems += _facet_problems(lines, first, facet, end, vertex)
    if not facet.any():
        problems.append("no triangles: no 'facet' line")
    content = np.flatnonzero(first < lines.ends)
    if not _starts_with(lines, first, b"endsolid")[content[-1]]:
        problems.append(f"the last line is not 'endsolid' but '{lines.text(content[-1])}' "
                        f"(line {content[-1] + 1}: a cut file?)")
    if problems:
        raise ValueError(f"'{path}' is not a valid ASCII STL triangle mesh: " + "; ".join(problems))
    return TextMesh(V, np.arange(V.shape[0], dtype=np.int64).reshape(-1, 3), 0)


def _starts_with(lines, first, word):
    """(L,) bool: the line's first word starts with ``word`` (as libigl tests it)."""
    buf, hit = lines.buf, first + len(word) <= lines.ends
    for k, byte in enumerate(word):
        hit &= buf[np.minimum(first + k, len(buf) - 1)] == byte
    return hit


def _vertices(lines, first, vertex):
    """(3 m, 3) coordinates of the ``vertex`` lines and the problems found in them."""
    chunk = lines.chunk(vertex, skip=first - lines.starts + len(b"vertex"))
    values, status = chunk.numbers("float")
    start = np.cumsum(chunk.counts) - chunk.counts
    has3 = chunk.counts >= 3
    V = np.full((len(chunk.counts), 3), np.nan)
    V[has3] = values[start[has3, None] + np.arange(3)]
    bad = np.zeros(len(V), dtype=bool)
    bad[has3] = (status[start[has3, None] + np.arange(3)] == BAD).any(axis=1)
    nonfinite = has3 & ~bad & ~np.isfinite(V).all(axis=1)
    found = [first_of(chunk.lines[~has3], lines, "vertex lines with fewer than 3 coordinates"),
             first_of(chunk.lines[bad], lines, "vertex lines with non-numeric coordinates"),
             first_of(chunk.lines[nonfinite], lines,
                      "vertices with non-finite coordinates (nan, inf or overflow)")]
    return V, [p for p in found if p]


def _facet_problems(lines, first, facet, end, vertex):
    """Facets without ``normal nx ny nz``, without three vertex lines or without ``endfacet``."""
    chunk = lines.chunk(facet, skip=first - lines.starts + len(b"facet"))
    buf = chunk.buf  # a copy of the facet lines, "facet" blanked
    at = np.array([m.end() for m in _NORMAL.finditer(buf.tobytes())], dtype=np.int64)
    buf[(at[:, None] - np.arange(1, len(b"normal") + 1)).ravel()] = 32  # "normal" blanked
    named = np.zeros(len(chunk.offsets), dtype=bool)
    named[np.searchsorted(chunk.offsets, at, side="right") - 1] = True
    normal = Chunk(buf, chunk.offsets, chunk.lines)  # the tokens counted again
    values, status = normal.numbers("float")
    start = np.cumsum(normal.counts) - normal.counts
    ok = named & (normal.counts >= 3)
    ok[ok] = (status[start[ok, None] + np.arange(3)] != BAD).all(axis=1)
    facets, ends, verts = np.flatnonzero(facet), np.flatnonzero(end), np.flatnonzero(vertex)
    owner = np.searchsorted(facets, verts, side="right") - 1  # the facet before each vertex line
    per_facet = np.bincount(owner[owner >= 0], minlength=facets.size)
    following = np.append(facets[1:], len(lines.starts))  # each facet's next facet (or the end)
    closed = np.searchsorted(ends, facets) < np.searchsorted(ends, following)
    found = [first_of(facets[~ok], lines, "facet lines without 'normal nx ny nz'"),
             first_of(facets[per_facet != 3], lines,
                      "facets without exactly 3 vertex lines (a cut or joined file?)"),
             first_of(facets[~closed], lines, "facets without 'endfacet'"),
             first_of(verts[owner < 0], lines, "vertex lines before the first facet")]
    return [p for p in found if p]

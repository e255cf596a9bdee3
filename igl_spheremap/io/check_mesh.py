"""Strict check of a MEDIT ``.mesh`` file in the layout libigl reads, before libigl reads it."""

import re
from pathlib import Path

import numpy as np

from ..errors import plural
from .check_obj import TextMesh, refuse_binary
from .line_scan import BLANKS, SCANF_NUMBER, Lines

#: libigl's MEDIT reader reads its keyword lines with ``fgets`` into a buffer of this many
#: bytes (``LINE_MAX``): a longer line is read in pieces.
LIBIGL_MESH_LINE_MAX = 2047

#: Most vertices libigl's MEDIT reader accepts.
MAX_VERTICES = 1_000_000_000

_INT = re.compile(BLANKS + rb"([+-]?\d{1,9})(?!\d)")


def check_mesh(path, data=None):
    """Parse a MEDIT ``.mesh`` file as libigl's reader does; raise on anything it would misread.

    libigl's MEDIT reader (2.6.3) expects, in this order, ``MeshVersionFormatted 1``,
    ``Dimension 3``, ``Vertices`` with its count on the next line and ``x y z ref`` rows,
    ``Triangles`` with its count and ``i j k ref`` rows (1-based), ``Tetrahedra`` with its
    count and ``i j k l ref`` rows; lines starting with ``#`` and empty lines before a
    keyword are skipped and anything after the tetrahedra is ignored.  A count on its
    keyword's line is read as part of the rows, and ``igl.read_triangle_mesh`` has returned,
    for a file cut in its rows, faces of uninitialised indices that differ from run to run
    and are sometimes in range.  This check follows the same reading and refuses, with its
    line, anything libigl would not read as written.

    Parameters
    ----------
    path : str or os.PathLike
        The file (also named in messages).
    data : bytes, optional
        Its content, when already read.

    Returns
    -------
    TextMesh
        Vertices, triangles (0-based) and ``polygons`` 0.

    Raises
    ------
    ValueError
        The first problem found, with its line: binary content, a keyword missing or
        out of order, a version other than 1 or a dimension other than 3, values on a
        ``Vertices`` / ``Triangles`` / ``Tetrahedra`` line, a count that is not a
        non-negative integer, a row cut short or with a non-number, non-finite
        coordinates or triangle indices out of range (their counts), no triangles.
    """
    data = Path(path).read_bytes() if data is None else data
    lines = Lines(data)
    refuse_binary(path, lines, "MEDIT")
    reader = _Reader(path, lines, lines.buf.tobytes())
    reader.keyword(b"MeshVersionFormatted", value=1)
    reader.keyword(b"Dimension", value=3)
    n = reader.count(b"Vertices", MAX_VERTICES)
    V = np.array([reader.row(SCANF_NUMBER, 3, "vertex") for _ in range(n)],
                 dtype=np.float64).reshape(-1, 3)
    m = reader.count(b"Triangles")
    F = np.array([reader.row(_INT, 3, "triangle") for _ in range(m)],
                 dtype=np.int64).reshape(-1, 3) - 1
    for _ in range(reader.count(b"Tetrahedra")):
        reader.row(_INT, 4, "tetrahedron")
    problems = []
    bad_v = np.flatnonzero(~np.isfinite(V).all(axis=1))
    if bad_v.size:
        problems.append(f"{plural(bad_v.size, 'vertex', 'vertices')} with non-finite coordinates "
                        f"(first: vertex {bad_v[0] + 1})")
    bad_f = np.flatnonzero(((F < 0) | (F >= n)).any(axis=1))
    if bad_f.size:
        problems.append(f"{plural(bad_f.size, 'triangle')} with indices out of range (valid: 1 "
                        f"to {n}; first: triangle {bad_f[0] + 1})")
    if m == 0:
        problems.append("no triangles")
    if problems:
        raise ValueError(f"'{path}' is not a MEDIT triangle mesh libigl reads: "
                         + "; ".join(problems))
    return TextMesh(V, F, 0)


class _Reader:
    """A read position in the file, moved as libigl's ``fgets`` and ``fscanf`` calls move it."""

    def __init__(self, path, lines, buf):
        self.path, self.lines, self.buf, self.pos = path, lines, buf, 0

    def fail(self, what, pos=None):
        k = self.lines.line_at(self.pos if pos is None else pos)
        raise ValueError(f"'{self.path}' is not a MEDIT triangle mesh libigl reads: {what} "
                         f"(line {k + 1}: '{self.lines.text(k)}')")

    def keyword_line(self, word):
        """The words of the next line that is not empty or a ``#`` comment, from the read
        position (the rest of the current line first, as ``fgets`` reads on)."""
        while True:
            if self.pos >= len(self.buf):
                self.fail(f"the file ends before '{word.decode()}' (a cut file?)", self.pos - 1)
            end = self.buf.find(b"\n", self.pos)
            end = len(self.buf) if end < 0 else end + 1
            line, start, self.pos = self.buf[self.pos:end], self.pos, end
            if len(line) > LIBIGL_MESH_LINE_MAX:
                self.fail(f"a line longer than {LIBIGL_MESH_LINE_MAX} bytes, which libigl's "
                          "reader reads in pieces", start)
            if line[:1] not in (b"#", b"\n"):
                words = line.split()
                if not words or words[0] != word:
                    hint = (" (a Windows line end: libigl's reader skips '\\n' alone, not "
                            "'\\r\\n')" if line.strip() == b"" and b"\r" in line else "")
                    self.fail(f"expected '{word.decode()}' here{hint}", start)
                return words[1:], start

    def keyword(self, word, value):
        """``word`` and its integer ``value``, on its line or as the next number."""
        rest, start = self.keyword_line(word)
        got = rest[0] if rest else self.token(_INT, f"the value of '{word.decode()}'")
        if got != str(value).encode():
            self.fail(f"'{word.decode()}' must be {value} for libigl's reader, not "
                      f"{got.decode('utf-8', 'replace')}", start)

    def count(self, word, most=None):
        """The count after ``word``'s line (libigl reads it with ``fscanf``, after the line)."""
        rest, start = self.keyword_line(word)
        if rest:
            self.fail(f"values after '{word.decode()}' on its line, which libigl's reader "
                      "skips: put the count on the next line", start)
        n = int(self.token(_INT, f"the count of '{word.decode()}'"))
        if n < 0 or (most is not None and n > most):
            self.fail(f"the count of '{word.decode()}' must be 0 to {most or '10^9'}, not {n}")
        return n

    def row(self, pattern, width, what):
        """One row: ``width`` numbers of ``pattern`` and an integer reference (dropped)."""
        out = [self.token(pattern, what) for _ in range(width)]
        self.token(_INT, f"the reference number of a {what}")
        return out

    def token(self, pattern, what):
        m = pattern.match(self.buf, self.pos)
        if m is None:
            rest = self.buf[self.pos:].split()
            found = repr(rest[0].decode("utf-8", "replace")) if rest else "the end of the file"
            self.fail(f"expected {what} (a number), found {found}",
                      self.pos + len(self.buf[self.pos:]) - len(self.buf[self.pos:].lstrip()))
        self.pos = m.end()
        return m.group(1)

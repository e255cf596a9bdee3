"""Vectorized scanning of line-based text mesh files (OBJ, OFF): lines, tokens, numbers.

Everything runs on NumPy views of the file's bytes; the only Python loops are
over 4096-line blocks that numpy's parser rejected (a file with problems).
"""

import re
import warnings

import numpy as np

#: ASCII whitespace, as ``bytes.split`` sees it.
WHITESPACE = np.zeros(256, dtype=bool)
WHITESPACE[[9, 10, 11, 12, 13, 32]] = True

#: A decimal number as ``strtod`` reads it (``nan``, ``inf`` included; case-insensitive), and
#: the blanks ``scanf``'s ``" "`` skips: the readers that mimic libigl's ``fscanf`` loops build
#: their token patterns from these.
NUMBER = rb"[+-]?(?:(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|nan|inf(?:inity)?)"
BLANKS = rb"[ \t\n\v\f\r]*"

#: The next number as ``fscanf(" %lf")`` reads it: blanks, then the longest match of
#: :data:`NUMBER` (group 1), as ``strtod`` takes it.
SCANF_NUMBER = re.compile(BLANKS + b"(" + NUMBER + b")", re.I)

_FLOAT = re.compile(NUMBER, re.I)
_INT = re.compile(rb"[+-]?\d+")
_BLOCK = 4096  # lines per block of the slow path

#: Status of a token from :meth:`Chunk.numbers`.
INTEGER, DECIMAL, BAD = 0, 1, 2


class Lines:
    """A file's lines as byte offsets into its content.

    Parameters
    ----------
    data : bytes
        The whole file.  A final newline is added when missing.

    Attributes
    ----------
    buf : (N,) uint8 array
        The bytes, ending with ``b"\\n"``.
    starts, ends : (L,) int64 arrays
        Offset of each line's first byte and of its ``"\\n"``; line ``i`` is
        line number ``i + 1``.
    """

    def __init__(self, data):
        if not data.endswith(b"\n"):
            data = data + b"\n"
        self.buf = np.frombuffer(data, dtype=np.uint8)
        self.ends = np.flatnonzero(self.buf == 10)
        self.starts = np.concatenate(([0], self.ends[:-1] + 1)).astype(np.int64)

    def control_bytes(self):
        """Indices of lines holding bytes below 32 other than whitespace (binary content)."""
        pos = np.flatnonzero((self.buf < 9) | ((self.buf > 13) & (self.buf < 32)))
        return np.unique(np.searchsorted(self.ends, pos))

    def line_at(self, offset):
        """Index (0-based) of the line holding byte ``offset`` (past the end: the last line)."""
        return min(int(np.searchsorted(self.ends, offset)), len(self.ends) - 1)

    def byte(self, k):
        """(L,) uint8: byte ``k`` of every line (past a line's end: its newline or later bytes)."""
        return self.buf[np.minimum(self.starts + k, len(self.buf) - 1)]

    def first_token_start(self):
        """(L,) int64: offset of each line's first non-blank byte (``ends`` for blank lines)."""
        first = self.starts.copy()
        lead = np.flatnonzero(WHITESPACE[self.buf[self.starts]] & (self.starts < self.ends))
        for i in lead:  # indented lines only
            s, e = self.starts[i], self.ends[i]
            line = self.buf[s:e].tobytes()
            first[i] = s + len(line) - len(line.lstrip())
        return first

    def text(self, i, width=60):
        """Line ``i`` as text (stripped, shortened to ``width`` characters) for messages."""
        line = self.buf[self.starts[i]:self.ends[i]].tobytes().decode("utf-8", "replace").strip()
        return line if len(line) <= width else line[: width - 3] + "..."

    def chunk(self, select, skip=None):
        """The selected lines as one :class:`Chunk`.

        Parameters
        ----------
        select : (L,) bool array
        skip : (L,) int array, optional
            Bytes to blank at the start of each line (a keyword such as ``v``).
        """
        idx = np.flatnonzero(select)
        lengths = self.ends[idx] - self.starts[idx] + 1
        run = np.flatnonzero(np.diff(idx) != 1)
        first, last = np.append(idx[:1], idx[run + 1]), np.append(idx[run], idx[-1:])
        if len(first) <= 256:  # a few blocks of consecutive lines: copy slices
            out = np.concatenate([self.buf[self.starts[a]:self.ends[b] + 1]
                                  for a, b in zip(first, last)] or [np.zeros(0, np.uint8)])
        else:
            out = self.buf[np.repeat(select, self.ends - self.starts + 1)]
        offsets = (np.cumsum(lengths) - lengths).astype(np.int64)
        if skip is not None:
            k = np.asarray(skip)[idx]
            blank = np.repeat(offsets, k) + (np.arange(k.sum()) - np.repeat(np.cumsum(k) - k, k))
            out[blank] = 32
        return Chunk(out, offsets, idx)


class Chunk:
    """Selected lines of a file, concatenated, with their tokens counted.

    Attributes
    ----------
    buf : (N,) uint8 array
    offsets : (k,) int64 array
        Start of each line in ``buf``.
    lines : (k,) int64 array
        Index of each line in the file (line number minus one).
    counts : (k,) int64 array
        Number of whitespace-separated tokens on each line.
    """

    def __init__(self, buf, offsets, lines):
        self.buf, self.offsets, self.lines = buf, offsets, lines
        ws = buf <= 32  # whitespace, given no other control bytes (Lines.control_bytes)
        starts = ~ws
        starts[1:] &= ws[:-1]
        first_token = np.searchsorted(np.flatnonzero(starts), np.append(offsets, len(buf)))
        self.counts = np.diff(first_token).astype(np.int64)

    def token_line(self):
        """(T,) int64: index into ``lines`` of every token."""
        return np.repeat(np.arange(len(self.counts)), self.counts)

    def numbers(self, kind):
        """Parse every token as a number.

        Parameters
        ----------
        kind : {"float", "int"}
            ``"int"`` parses integers and also classifies decimal tokens.

        Returns
        -------
        values : (T,) float64 array
            The numbers (NaN where the token is not a number).
        status : (T,) int8 array
            ``INTEGER`` / ``DECIMAL`` / ``BAD`` per token; with ``kind="float"``
            every number is ``DECIMAL``.
        """
        total = int(self.counts.sum())
        values = _fromstring(self.buf.tobytes(), kind, total)
        if values is not None:
            return values, np.full(total, INTEGER if kind == "int" else DECIMAL, dtype=np.int8)
        values = np.empty(total, dtype=np.float64)
        status = np.empty(total, dtype=np.int8)
        bounds = np.append(self.offsets, len(self.buf))
        first_token = np.concatenate(([0], np.cumsum(self.counts)))
        for b in range(0, len(self.offsets), _BLOCK):
            e = min(b + _BLOCK, len(self.offsets))
            t0, t1 = first_token[b], first_token[e]
            text = self.buf[bounds[b]:bounds[e]].tobytes()
            got = _fromstring(text, kind, t1 - t0)
            if got is not None:
                values[t0:t1] = got
                status[t0:t1] = INTEGER if kind == "int" else DECIMAL
            else:
                values[t0:t1], status[t0:t1] = _parse_tokens(text.split(), kind)
        return values, status


def _fromstring(text, kind, expected):
    """NumPy's C parser on whitespace-separated numbers; None unless exactly ``expected`` parse."""
    if expected == 0:
        return np.zeros(0)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            got = np.fromstring(text, sep=" ", dtype=np.int64 if kind == "int" else np.float64)
    except (ValueError, DeprecationWarning):
        return None
    if len(got) != expected:
        return None
    if kind == "int" and np.any(np.abs(got) == np.iinfo(np.int64).max):
        return None  # saturated: let the slow path classify it
    return got.astype(np.float64)


def _parse_tokens(tokens, kind):
    """Token by token, for a block numpy's parser rejected."""
    values = np.full(len(tokens), np.nan)
    status = np.full(len(tokens), BAD, dtype=np.int8)
    for i, tok in enumerate(tokens):
        if kind == "int" and _INT.fullmatch(tok):
            values[i], status[i] = float(int(tok)), INTEGER
        elif _FLOAT.fullmatch(tok):
            values[i], status[i] = float(tok), DECIMAL
    return values, status


def first_of(rows, lines, what):
    """Message part ``"<what>: N (first on line K: '<text>')"`` for flagged line indices."""
    rows = np.asarray(rows)
    if rows.size == 0:
        return None
    first = int(rows.min())
    return f"{what}: {rows.size} (first on line {first + 1}: '{lines.text(first)}')"

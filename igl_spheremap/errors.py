"""Exception types raised by igl_spheremap."""


class MeshError(ValueError):
    """The input mesh violates a precondition of the spherical conformal map.

    Raised by :func:`igl_spheremap.validate_mesh` (and everything that calls
    it) when the input is not a closed, manifold, connected, genus-0 triangle
    mesh with finite coordinates and non-degenerate faces, and by the intrinsic
    Delaunay Laplacian (:func:`igl_spheremap.mesh.operators.laplacian`) on a mesh
    with slivers (``problem="slivers"``).  The message names
    the problem and the number of offending elements; ``problem`` holds a short
    machine-readable key and ``count`` the number of offending elements.
    """

    def __init__(self, problem, count, message):
        super().__init__(message)
        self.problem = problem
        self.count = int(count)

    @classmethod
    def invalid(cls, problem, count, text):
        """``MeshError(problem, count, "invalid mesh (<problem>): <text>")``, the house format."""
        return cls(problem, count, f"invalid mesh ({problem}): {text}")


class SphericalMapWarning(UserWarning):
    """The returned map has folded faces or its last Algorithm 1 run did not converge."""


def plural(k, one, many=None):
    """``"1 face"``, ``"3 faces"``: a count with the noun in the right number (str)."""
    return f"{k} {one if k == 1 else many or one + 's'}"


def one_line(text):
    """``text`` collapsed to one line (non-empty lines stripped and joined by '; '), characters
    that do not print escaped (``\\x1b``): a message quoting a line of a damaged file must not
    move the cursor, clear the terminal or break a summary table."""
    line = "; ".join(s.strip() for s in str(text).splitlines() if s.strip())
    return "".join(c if c.isprintable() else c.encode("unicode_escape").decode("ascii")
                   for c in line)


def describe(exc):
    """One line saying what went wrong, for the command line and batch summaries.

    ``"invalid mesh: <problem and count>"`` for a :class:`MeshError`, the message
    for ``OSError`` / ``ValueError`` (they carry the path or the bad value), and
    ``"<type>: <message>"`` for anything else.

    Parameters
    ----------
    exc : BaseException

    Returns
    -------
    str
    """
    text = one_line(exc)
    if isinstance(exc, MeshError):
        prefix = f"invalid mesh ({exc.problem}):"
        return "invalid mesh: " + (text[len(prefix):].lstrip() if text.startswith(prefix)
                                   else text)
    if isinstance(exc, (OSError, ValueError)) and text:
        return text
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__

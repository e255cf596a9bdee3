"""Kept for imports of ``one_line`` from here; the helper lives in :mod:`._text`.

The former ``captured_stderr_fd`` (a process-wide ``dup2`` of file descriptor 2)
is gone: libigl's own diagnostics go to stderr untouched, and the exceptions of
:mod:`igl_spheremap.io` carry messages that stand on their own.
"""

from ._text import one_line

__all__ = ["one_line"]

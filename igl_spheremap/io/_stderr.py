"""Capture what C++ code (libigl's readers and writers) prints on file descriptor 2."""

import contextlib
import os
import sys
import tempfile


@contextlib.contextmanager
def captured_stderr_fd(sink):
    """Redirect fd 2 into a temporary file; append its text to the list ``sink``.

    libigl reports read/write failures on the process's stderr before raising;
    the CLI turns failures into one-line messages, so that text is captured and
    folded into the exception message instead.  Falls back to doing nothing when
    fd 2 cannot be duplicated.
    """
    try:
        sys.stderr.flush()
        saved = os.dup(2)
    except (OSError, ValueError, AttributeError):
        yield
        return
    with tempfile.TemporaryFile() as tmp:
        os.dup2(tmp.fileno(), 2)
        try:
            yield
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            tmp.seek(0)
            sink.append(tmp.read().decode("utf-8", "replace"))


def one_line(text):
    """Collapse captured text to one line (non-empty lines joined by '; ')."""
    return "; ".join(s.strip() for s in text.splitlines() if s.strip())

"""Atomic file replacement: write to a temporary sibling, then ``os.replace``."""

import contextlib
import os
import uuid
from pathlib import Path


@contextlib.contextmanager
def atomic_path(path):
    """Yield a temporary path next to ``path``; move it onto ``path`` on success.

    The temporary name keeps the whole file name of ``path`` at its end
    (``.tmp-<token>-lh.white_sphere.surf.gii``), so writers that pick the
    format from the extension (libigl, nibabel) see the right one.  If the
    body raises, the temporary file is removed and ``path`` is left untouched,
    so a crash never leaves a half-written file under the final name.

    Parameters
    ----------
    path : str or os.PathLike
        Final destination.  Its parent directory must exist.

    Yields
    ------
    pathlib.Path
        Where the body must write.

    Raises
    ------
    FileNotFoundError
        ``path``'s folder does not exist (named, not the temporary file a writer
        would fail on).
    """
    path = Path(path)
    if not path.parent.is_dir():
        raise FileNotFoundError(f"cannot write '{path}': no such folder '{path.parent}'")
    tmp = path.with_name(f".tmp-{uuid.uuid4().hex[:12]}-{path.name}")
    try:
        yield tmp
        os.replace(tmp, path)
    finally:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()

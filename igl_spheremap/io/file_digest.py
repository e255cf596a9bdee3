"""The SHA-256 digest of a file's content: what a batch run's report records of its input and
outputs, so that a rerun can tell a finished mesh from a changed one."""

import hashlib

#: Bytes read at a time.
CHUNK = 1 << 20


def file_digest(path):
    """Hex SHA-256 of the file at ``path``, or None if it cannot be read.

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    str or None
        64 hexadecimal digits; None for a missing or unreadable file (a rerun then
        counts the mesh as not done).
    """
    digest = hashlib.sha256()
    try:
        with open(path, "rb") as fh:
            for block in iter(lambda: fh.read(CHUNK), b""):
                digest.update(block)
    except OSError:
        return None
    return digest.hexdigest()

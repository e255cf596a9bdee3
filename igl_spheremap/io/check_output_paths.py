"""Check, before mapping, that every output can be written and overwrites nothing it should not."""

import os
import tempfile
from pathlib import Path

from .check_sphere_output import check_sphere_output
from .output_paths import OutputPaths


def check_output_paths(input_path, paths, report_path=None, data_path=None):
    """Refuse outputs that would fail or do harm, before any work; create and leave nothing.

    Checks, in order:

    1. the sphere's format stores the map vertex for vertex
       (:func:`check_sphere_output`: no ``.stl``, ``.wrl``, ``.mesh``, ``.msh``);
    2. no output is the input mesh (resolved paths, symbolic links followed,
       and the same file under two names for existing files);
    3. no two outputs are the same file, and none is an existing folder;
    4. the folder of every output is writable: if it exists, it must be a
       folder in which a temporary file can be created (and is removed at
       once; ``os.access`` alone is not trusted, e.g. as root on a read-only
       file system); if it is missing, its nearest existing ancestor must be
       such a folder and must not be the file system root (a missing
       ``/newdir`` is refused: create it first).

    Missing folders below an existing, writable, non-root folder are allowed;
    this function does not create them: the caller does, right before
    writing (``Path.mkdir(parents=True, exist_ok=True)``, as
    :func:`igl_spheremap.app.map_file.map_file` does).

    Parameters
    ----------
    input_path : str or os.PathLike
        The mesh being mapped.
    paths : OutputPaths or str or os.PathLike
        The outputs (:func:`output_paths`), of which the sphere is always
        written; or the sphere's path alone.
    report_path, data_path : str or os.PathLike, optional
        The report and per-vertex data files that will be written (None: not
        written; the defaults in ``paths`` are not checked unless passed here).

    Returns
    -------
    dict of str -> pathlib.Path
        The outputs checked, by role (``"sphere"``, ``"data"``, ``"report"``),
        as given.

    Raises
    ------
    ValueError
        A refused sphere format, an output that is the input, two outputs on
        one file, or a missing folder that would be created at the root.
    IsADirectoryError
        An output names an existing folder.
    NotADirectoryError
        An output's folder, or an ancestor of it, is a file.
    PermissionError
        An output's folder (or nearest existing ancestor) is not writable.
    """
    if isinstance(paths, OutputPaths):
        sphere, family = paths.sphere, paths.family
    else:
        sphere, family = Path(paths), None
    check_sphere_output(sphere, family)
    return check_outputs([input_path], {"sphere": sphere, "data": data_path,
                                        "report": report_path})


def check_outputs(inputs, outputs):
    """Checks 2-4 of :func:`check_output_paths` for any files.

    Parameters
    ----------
    inputs : list of str or os.PathLike
        Files that must not be overwritten (the inputs).
    outputs : dict of str -> str or os.PathLike or None
        Output paths by role (None entries are skipped).

    Returns
    -------
    dict of str -> pathlib.Path
        The outputs checked, by role.

    Raises
    ------
    ValueError, IsADirectoryError, NotADirectoryError, PermissionError
        As :func:`check_output_paths`.
    """
    outputs = {role: Path(p) for role, p in outputs.items() if p is not None}
    seen = {}
    for role, path in outputs.items():
        target = path.resolve()
        for source in map(Path, inputs):
            if target == source.resolve() or _same_file(path, source):
                raise ValueError(f"the {role} output '{path}' would overwrite the input "
                                 f"'{source}'")
        if target in seen:
            raise ValueError(f"the {role} output and the {seen[target]} output are the same "
                             f"file '{path}'")
        seen[target] = role
        if target.is_dir():
            raise IsADirectoryError(f"the {role} output '{path}' is an existing folder")
    for folder in dict.fromkeys(p.resolve().parent for p in outputs.values()):
        _check_folder(folder)
    return outputs


def _same_file(a, b):
    try:
        return os.path.samefile(a, b)
    except OSError:  # one of them does not exist
        return False


def _check_folder(folder):
    """Raise unless files can be written in ``folder`` or it can be made below a writable one."""
    existing, missing = folder, []
    while not existing.exists() and existing.parent != existing:
        missing.append(existing)
        existing = existing.parent
    if not existing.is_dir():
        raise NotADirectoryError(f"cannot write into '{folder}': '{existing}' is not a folder")
    if missing and existing.parent == existing:
        raise ValueError(f"writing into '{folder}' would create folder {missing[-1]} at the file "
                         "system root; create it first")
    try:
        fd, probe = tempfile.mkstemp(prefix=".igl-spheremap-probe-", dir=existing)
    except OSError as exc:
        what = f"folder '{existing}'" + (f" (to create '{folder}' in)" if missing else "")
        raise PermissionError(f"cannot write into {what}: {exc.strerror or exc}") from None
    os.close(fd)
    os.unlink(probe)

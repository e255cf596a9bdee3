"""A mesh file read and validated, its faults named with the file's role: what the commands that
take two surfaces (``register``, ``register-sphere``) read each input with."""

from ..errors import MeshError
from ..io import read_mesh
from ..mesh.validate import validate_mesh


def read_surface(path, role, return_metadata=False):
    """:func:`igl_spheremap.io.read_mesh` of ``path``, then :func:`igl_spheremap.validate_mesh`.

    Parameters
    ----------
    path : str or os.PathLike
    role : str
        What the file is to the command (``"surface 1"``, ``"the target sphere"``), put in
        front of the validation's message with the file's name, so that of two inputs the
        bad one is named.
    return_metadata : bool, default False
        As in :func:`igl_spheremap.io.read_mesh`.

    Returns
    -------
    :func:`igl_spheremap.io.read_mesh`'s tuple, the arrays as read (not the validated
    mesh's: the callers validate again where they map).

    Raises
    ------
    MeshError
        The mesh is not a closed genus-0 triangle mesh: the same ``problem`` and ``count``,
        the message prefixed with ``role`` and the file.
    ValueError, OSError
        As :func:`igl_spheremap.io.read_mesh`.
    """
    out = read_mesh(path, return_metadata=return_metadata)
    try:
        validate_mesh(out[0], out[1])
    except MeshError as err:
        raise MeshError(err.problem, err.count, f"{role} '{path}': {err}") from None
    return out

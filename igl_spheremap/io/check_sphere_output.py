"""Refuse, before any work, sphere outputs that cannot carry the map vertex for vertex."""

from pathlib import Path

from .mesh_format import mesh_format

#: Outputs that keep the vertex order and every coordinate of the map.
SPHERE_FORMATS = ".obj, .off, .ply, .surf.gii or a FreeSurfer name such as lh.sphere"

#: Mesh extensions that cannot store a spherical map vertex for vertex, and why (lower case).
REFUSED_FORMATS = {
    ".stl": "STL keeps no per-vertex correspondence (every triangle stores its own three "
            "corners, as float32), so the sphere could not be matched to the input's vertices",
    ".wrl": "libigl writes VRML with about 15 significant digits, so the stored map can fold "
            "where the map in memory does not",
    ".mesh": "libigl's .mesh files hold tetrahedra: the triangles are not read back",
    ".msh": "libigl cannot write triangle surfaces as .msh",
}


def check_sphere_output(path, family=None, role="sphere"):
    """Check that ``path`` names a format that stores a spherical map vertex for vertex.

    Call it before mapping, so that a refused name costs nothing.
    :func:`igl_spheremap.io.write_mesh` itself still writes STL and VRML for
    other uses.

    Parameters
    ----------
    path : str or os.PathLike
        The sphere's output name.
    family : str, optional
        Its format family (default: :func:`mesh_format` of the name).
    role : str
        What the file holds, for the messages (the sphere, a resampled surface).

    Returns
    -------
    str
        The format family: ``"mesh"`` (``.obj``, ``.off``, ``.ply``), ``"gifti"``
        or ``"freesurfer"``.

    Raises
    ------
    ValueError
        The format cannot be told from the name, or it is ``.stl`` (no
        per-vertex correspondence), ``.wrl`` (not exact), ``.mesh`` / ``.msh``
        (no triangle surface round trip).
    """
    path = Path(path)
    family = family or mesh_format(path, must_exist=False)
    if family is None:
        raise ValueError(f"cannot tell the output format of '{path}' from its name: use "
                         f"{SPHERE_FORMATS}")
    reason = REFUSED_FORMATS.get(path.suffix.lower()) if family == "mesh" else None
    if reason:
        reason = reason.replace("the sphere", f"the {role}")
        raise ValueError(f"cannot write the {role} to '{path}': {reason}; use {SPHERE_FORMATS}")
    return family

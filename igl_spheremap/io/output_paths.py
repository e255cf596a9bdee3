"""Default names of the files written for one mapped mesh."""

from dataclasses import dataclass
from pathlib import Path

from .check_sphere_output import REFUSED_FORMATS
from .mesh_format import mesh_format


@dataclass(frozen=True)
class OutputPaths:
    """Where the outputs of one mesh go.

    Attributes
    ----------
    sphere : pathlib.Path
        The spherical mesh.
    family : str
        Its format family (``"mesh"``, ``"gifti"``, ``"freesurfer"``).
    data : pathlib.Path
        Per-vertex data (``.npz`` for the mesh family, ``.func.gii`` otherwise).
    report : pathlib.Path
        JSON run report.
    """

    sphere: Path
    family: str
    data: Path
    report: Path


#: Extensions of other tools' mesh, volume and data files: an output so named after a FreeSurfer
#: input is refused, not written as a FreeSurfer surface under that name.
FOREIGN_EXTENSIONS = (".vtk", ".vtp", ".vtu", ".gltf", ".glb", ".fbx", ".3ds", ".dae", ".x3d",
                      ".asc", ".srf", ".nii", ".mgh", ".mgz", ".json", ".npz", ".npy", ".txt",
                      ".csv", ".h5", ".hdf5", ".xyz", ".pts")


def _split(name, family):
    """(base, extension) of a file name, GIfTI double extensions included."""
    low = name.lower()
    if family == "gifti":
        for ext in (".surf.gii.gz", ".gii.gz", ".surf.gii", ".gii"):
            if low.endswith(ext):
                return name[: -len(ext)], name[-len(ext):]
    if family == "mesh":
        p = Path(name)
        return p.stem, p.suffix
    return name, ""


def output_paths(input_path, output=None, *, input_family=None, outdir=None):
    """Output names for mapping ``input_path``.

    Without ``output`` the sphere is ``<outdir>/<stem>_sphere<ext>`` where the
    stem drops the format extension and the extension is the input's
    (``dino.obj -> dino_sphere.obj``, ``lh.white.surf.gii -> lh.white_sphere.surf.gii``,
    ``.gii`` and ``.gii.gz -> _sphere.surf.gii``, FreeSurfer ``lh.white -> lh.white_sphere``),
    or ``.obj`` where the input's format cannot store the sphere
    (:data:`~igl_spheremap.io.check_sphere_output.REFUSED_FORMATS`: ``part.stl ->
    part_sphere.obj``).
    With ``output`` its format comes from its name (``.gii`` or ``.gii.gz`` GIfTI, a libigl
    extension, a FreeSurfer ``?h.*`` name) and otherwise from the input, so another
    name after a FreeSurfer input is a FreeSurfer surface, unless its extension is
    another tool's (:data:`FOREIGN_EXTENSIONS`: ``.vtk``, ``.nii``, ...).

    The data file and the report sit next to the sphere, with the sphere's base
    name: ``dino_sphere.npz`` / ``dino_sphere.json``, ``lh.white_sphere.func.gii``
    / ``lh.white_sphere.json``.

    Parameters
    ----------
    input_path : str or os.PathLike
    output : str or os.PathLike, optional
    input_family : str, optional
        Format family of the input (default: detected from ``input_path``).
    outdir : str or os.PathLike, optional
        Directory of the default sphere name (default: the current directory).
        Not used when ``output`` is given.

    Returns
    -------
    OutputPaths

    Raises
    ------
    ValueError
        The format of ``output`` cannot be told from its name and the input is
        a libigl mesh file.
    """
    input_path = Path(input_path)
    input_family = input_family or mesh_format(input_path, must_exist=False)
    if output is None:
        base, ext = _split(input_path.name, input_family)
        if input_family == "gifti":
            ext = ".surf.gii"
        elif input_family == "mesh" and ext.lower() in REFUSED_FORMATS:
            ext = ".obj"
        sphere = Path(outdir if outdir is not None else ".") / f"{base}_sphere{ext}"
        family = input_family
    else:
        sphere = Path(output)
        family = mesh_format(sphere, must_exist=False)
        if family is None:
            if input_family != "freesurfer" or sphere.suffix.lower() in FOREIGN_EXTENSIONS:
                raise ValueError(f"cannot tell the output format of '{sphere}' from its name: use "
                                 ".obj, .off, .ply, .surf.gii or a FreeSurfer name such as "
                                 "lh.sphere")
            family = "freesurfer"
    base, _ = _split(sphere.name, family)
    data_ext = ".npz" if family == "mesh" else ".func.gii"
    return OutputPaths(sphere=sphere, family=family, data=sphere.with_name(base + data_ext),
                       report=sphere.with_name(base + ".json"))

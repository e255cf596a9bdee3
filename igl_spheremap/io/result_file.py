"""Save and load a :class:`igl_spheremap.SphericalMapResult` as one ``.npz`` file (no pickles).

Every dataclass field of the result, of its rounds, of their Algorithm 1 runs
and of the validated mesh is stored: arrays (and lists of numbers) in the
archive, everything else as JSON in its ``meta`` entry.  Fields that the
installed classes do not have are ignored on loading, and fields missing from
the file take their defaults, so files survive additions to the classes.
"""

import dataclasses
import json
import numbers
from pathlib import Path

import numpy as np

from ..folding.result import Round, SphericalMapResult
from ..mesh.validate import ValidatedMesh
from ..optimize.result import Algorithm1Result
from ..options import MapOptions

_CLASSES = {cls.__name__: cls for cls in (SphericalMapResult, Round, Algorithm1Result,
                                          ValidatedMesh)}
#: Format version written to ``meta``.
FORMAT = 1


def save_result(path, result):
    """Write ``result`` to ``path`` (``numpy.savez_compressed``; parent folders are created).

    Parameters
    ----------
    path : str or os.PathLike
        ``.npz`` file.
    result : SphericalMapResult

    Raises
    ------
    TypeError
        If ``result`` holds a value that cannot be stored (not an array, number,
        string, list, dict, dataclass of this package or MapOptions).
    """
    arrays = {}
    meta = {"format": FORMAT, "result": _encode(result, "result", arrays)}
    arrays["meta"] = np.array(json.dumps(meta))
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "wb") as fh:  # a file object keeps savez from appending ".npz"
        np.savez_compressed(fh, **arrays)


def load_result(path):
    """Read a :class:`SphericalMapResult` written by :func:`save_result`.

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    SphericalMapResult

    Raises
    ------
    OSError
        If the file cannot be opened (FileNotFoundError, ...).
    ValueError
        If the file is not a result file of this package, or a damaged one (whatever
        the error numpy, zipfile or the decoding raised; its type is in the message).
    """
    try:
        with np.load(path, allow_pickle=False) as z:
            if "meta" not in z.files:
                raise ValueError(f"'{path}' is not a result file of igl_spheremap (no 'meta' "
                                 "entry)")
            meta = json.loads(str(z["meta"]))
            if not isinstance(meta, dict) or "result" not in meta:
                raise ValueError(f"'{path}' is not a result file of igl_spheremap")
            return _decode(meta["result"], z)
    except (OSError, ValueError):
        raise
    except Exception as exc:  # a damaged file: zipfile's, zlib's, KeyError, TypeError, ...
        raise ValueError(f"cannot read the result file '{path}': {type(exc).__name__}: "
                         f"{exc}") from None


def _encode(obj, key, arrays):
    if isinstance(obj, MapOptions):
        return {"__options__": {name: getattr(obj, name) for name in sorted(obj.explicit)}}
    if dataclasses.is_dataclass(obj) and type(obj).__name__ in _CLASSES:
        return {"__class__": type(obj).__name__,
                **{f.name: _encode(getattr(obj, f.name), f"{key}.{f.name}", arrays)
                   for f in dataclasses.fields(obj)}}
    if isinstance(obj, np.ndarray) or (isinstance(obj, list) and obj and all(
            isinstance(v, numbers.Number) for v in obj)):
        arrays[key] = np.asarray(obj)
        return {"__array__": key, "list": isinstance(obj, list)}
    if isinstance(obj, (list, tuple)):
        return [_encode(v, f"{key}.{i}", arrays) for i, v in enumerate(obj)]
    if isinstance(obj, dict):
        return {str(k): _encode(v, f"{key}.{k}", arrays) for k, v in obj.items()}
    if isinstance(obj, np.generic):
        return obj.item()
    if obj is None or isinstance(obj, (str, bool, int, float)):
        return obj
    raise TypeError(f"cannot store {type(obj).__name__} ({key}) in a result file")


def _decode(obj, z):
    if isinstance(obj, list):
        return [_decode(v, z) for v in obj]
    if not isinstance(obj, dict):
        return obj
    if "__array__" in obj:
        arr = z[obj["__array__"]]
        return arr.tolist() if obj.get("list") else arr
    if "__options__" in obj:
        return MapOptions(**obj["__options__"])
    if "__class__" in obj:
        cls = _CLASSES[obj["__class__"]]
        known = {f.name for f in dataclasses.fields(cls)}
        return cls(**{k: _decode(v, z) for k, v in obj.items() if k in known})
    return {k: _decode(v, z) for k, v in obj.items()}

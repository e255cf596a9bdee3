"""Write a run report as JSON, atomically."""

import json
import math
from pathlib import Path

import numpy as np

from ._atomic import atomic_path


def _plain(obj):
    """Turn numpy scalars/arrays and non-finite floats into JSON-safe values."""
    if isinstance(obj, dict):
        return {str(k): _plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_plain(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _plain(obj.tolist())
    if isinstance(obj, np.generic):
        return _plain(obj.item())
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    if isinstance(obj, Path):
        return str(obj)
    return obj


def write_report(path, report):
    """Write ``report`` as indented JSON to ``path`` (temporary file + ``os.replace``).

    NumPy values become plain numbers and lists; NaN and infinities become
    ``null`` so that strict JSON parsers accept the file.

    Parameters
    ----------
    path : str or os.PathLike
    report : dict
    """
    text = json.dumps(_plain(report), indent=2, allow_nan=False) + "\n"
    with atomic_path(path) as tmp:
        Path(tmp).write_text(text, encoding="utf-8")

"""Write a run report as JSON, atomically."""

import json
import math
from pathlib import Path

import numpy as np

from .atomic import atomic_path


def json_ready(obj):
    """JSON-safe copy of ``obj``: numpy scalars/arrays to Python values, NaN/inf to None, paths to str."""
    if isinstance(obj, dict):
        return {str(k): json_ready(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [json_ready(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return json_ready(obj.tolist())
    if isinstance(obj, np.generic):
        return json_ready(obj.item())
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
    text = json.dumps(json_ready(report), indent=2, allow_nan=False) + "\n"
    with atomic_path(path) as tmp:
        Path(tmp).write_text(text, encoding="utf-8")

"""The summary of a batch run: ``summary.csv`` and ``summary.md``, one row per mesh."""

import csv
import io as _io
from pathlib import Path

from .io._atomic import atomic_path

#: Columns of ``summary.csv`` / ``summary.md``, in order.
SUMMARY_COLUMNS = ("mesh", "vertices", "faces", "folds", "converged",
                   "angle_distortion_mean_deg", "angle_distortion_sd_deg", "energy_over_4pi",
                   "seconds", "status", "message", "output")



def _fmt(value):
    if value is None:
        return ""
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return f"{value:.4g}"
    return str(value)


def summary_markdown(rows):
    """The summary rows as a GitHub-flavoured markdown table (str)."""
    lines = ["| " + " | ".join(SUMMARY_COLUMNS) + " |",
             "|" + "|".join("---" for _ in SUMMARY_COLUMNS) + "|"]
    for r in rows:
        cells = [_fmt(r.get(c)).replace("|", "\\|").replace("\n", " ") for c in SUMMARY_COLUMNS]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def write_summary(rows, outdir):
    """Write ``summary.csv`` and ``summary.md`` (columns :data:`SUMMARY_COLUMNS`) in ``outdir``.

    Returns
    -------
    (pathlib.Path, pathlib.Path)
        The CSV and markdown paths.
    """
    outdir = Path(outdir)
    buf = _io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=SUMMARY_COLUMNS, extrasaction="ignore",
                            lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    paths = (outdir / "summary.csv", outdir / "summary.md")
    for path, text in zip(paths, (buf.getvalue(), summary_markdown(rows))):
        with atomic_path(path) as tmp:
            tmp.write_text(text, encoding="utf-8")
    return paths

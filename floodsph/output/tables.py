"""Result tables as CSV and markdown, for the workflows' reports.

Rows are dicts (one per run, point or variant). Floats are written with a format spec
(default ``.6g``: six significant digits), NaN as ``nan``; other values as ``str``.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np


def cell(value, spec: str = ".6g") -> str:
    """One table cell: floats (Python or numpy) formatted with ``spec``, NaN as ``nan``."""
    if isinstance(value, float | np.floating):
        return "nan" if math.isnan(value) else format(float(value), spec)
    return str(value)


def write_csv(path, rows: list[dict], columns=None, spec: str = ".6g") -> Path:
    """Write ``rows`` to ``path`` with a header of ``columns`` (default: the first row's keys)."""
    path = Path(path)
    columns = list(columns if columns is not None else rows[0])
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(columns)
        for row in rows:
            w.writerow([cell(row[c], spec) for c in columns])
    return path


def markdown(rows: list[dict], columns=None, spec: str = ".4g") -> str:
    """``rows`` as a markdown table (columns default to the first row's keys)."""
    columns = list(columns if columns is not None else rows[0])
    lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    lines += ["| " + " | ".join(cell(r[c], spec) for c in columns) + " |" for r in rows]
    return "\n".join(lines)

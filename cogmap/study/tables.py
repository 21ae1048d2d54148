"""Writers every study report shares: a markdown table, a CSV file, and (from :mod:`cogmap.plots`)
pyplot without a display and the figure writer."""

from __future__ import annotations

import csv
from pathlib import Path

from cogmap.plots import pyplot, save_figure

__all__ = ["md_table", "pyplot", "save_figure", "write_csv"]


def md_table(header, rows) -> str:
    """A markdown table of ``header`` and ``rows`` (cells written with ``str``)."""
    out = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(out)


def write_csv(path: Path, header, rows) -> None:
    """Write ``header`` and ``rows`` to the CSV file ``path``."""
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        w.writerows(rows)

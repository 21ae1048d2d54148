"""Writers every study report shares: a markdown table, a CSV file, and pyplot without a display."""

from __future__ import annotations

import csv
from pathlib import Path


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


def pyplot():
    """``matplotlib.pyplot`` on the Agg backend (figures written to files, no display needed)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt

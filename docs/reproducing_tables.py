"""Refresh the generated parts of docs/reproducing.md from docs/results/*/ (tables and times).

    python docs/reproducing_tables.py

Everything between ``<!-- TIMES -->`` and the next heading, and between ``<!-- TABLES -->`` and
``## Where and why we differ``, is rewritten from each study's ``table.md`` and ``study.json``.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ORDER = ["exploration-reduced", "exploration-full", "success-full", "goals-full", "drift-full", "obstacle-full",
         "scaling-full"]


def studies() -> list[tuple[str, Path]]:
    return [(name, DOCS / "results" / name) for name in ORDER if (DOCS / "results" / name / "table.md").exists()]


def times_table() -> str:
    rows = ["| study | scale | runs | wall clock | sum of run times |", "|---|---|---|---|---|"]
    for name, path in studies():
        meta = json.loads((path / "study.json").read_text())
        study, scale = name.rsplit("-", 1)
        rows.append(f"| {study} | {scale} | {meta['runs_done']}/{meta['runs_total']} | {meta['wall_s_total']:.0f} s "
                    f"| {meta['run_wall_s_total']:.0f} s |")
    return "\n".join(rows)


def tables() -> str:
    parts = []
    for name, path in studies():
        body = (path / "table.md").read_text().split("\n", 1)[1].strip()  # drop the study's own title
        figures = " ".join(f"![{png.stem}](results/{name}/{png.name})" for png in sorted(path.glob("*.png")))
        study, scale = name.rsplit("-", 1)
        section = f"### {study} ({scale}) — `docs/results/{name}/`\n\n{body}\n"
        parts.append(section + (f"\n{figures}\n" if figures else ""))
    return "\n".join(parts)


def main() -> None:
    page = DOCS / "reproducing.md"
    text = page.read_text()
    text = re.sub(r"(<!-- TIMES -->\n).*?(\n## )", lambda m: m.group(1) + times_table() + "\n" + m.group(2), text,
                  count=1, flags=re.S)
    text = re.sub(r"(<!-- TABLES -->\n).*?(\n## Where and why we differ)",
                  lambda m: m.group(1) + tables() + m.group(2), text, count=1, flags=re.S)
    page.write_text(text)


if __name__ == "__main__":
    main()

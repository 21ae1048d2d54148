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
ORDER = ["exploration-reduced", "exploration-full", "success-full", "goals-full", "drift-full", "slip-full",
         "dropout-full", "obstacle-full", "scaling-full"]


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


OLD_STARTS = "seed k started at `layout.starts[k mod n]`, so a row of 5 seeds held 3-4 distinct starts"
OLD_DEFINITIONS = {
    "exploration": "runs stopped at 99 % coverage, CE and nAUC at the end only, success = coverage >= 90 % and no "
                   "stall, " + OLD_STARTS + ", no `frontier_paper` row",
    "success": "runs stopped at 99 % coverage, success = coverage >= 90 % and no stall (5 failed moves in a row or 25 "
               "decisions without coverage gain), " + OLD_STARTS + ", no `frontier_paper` row",
    "drift": "runs stopped at 99 % coverage, " + OLD_STARTS + ", no success column, no `frontier_paper` row",
}


OLD_DEFINITIONS["goals"] = OLD_STARTS  # obstacle and scaling use fewer seeds than starts: nothing changed


def old_definitions_note(study: str) -> str:
    what = OLD_DEFINITIONS.get(study)
    if what is None:
        return ""
    return f"**Made under the previous definitions** ({what}); the definitions above apply from its next re-run.\n\n"


def made_under_old_definitions(meta: dict) -> bool:
    """Studies run before the endpoint/success/start definitions of this page have no success rule
    in their plan."""
    return "success_rule" not in meta.get("plan", {})


def tables() -> str:
    parts = []
    for name, path in studies():
        body = (path / "table.md").read_text().split("\n", 1)[1].strip()  # drop the study's own title
        study, scale = name.rsplit("-", 1)
        if made_under_old_definitions(json.loads((path / "study.json").read_text())):
            body = old_definitions_note(study) + body
        figures = " ".join(f"![{png.stem}](results/{name}/{png.name})" for png in sorted(path.glob("*.png")))
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

"""Every committed result names the clean commit it was made from.

``git_commit()`` appends ``+dirty`` when the working tree had uncommitted changes: such a table was
made by code that no commit holds, so nobody can re-make it. Each ``docs/results/<study>/`` must
name a full commit hash without ``+dirty`` in ``study.json`` and in the header of ``table.md``, and
the two must agree.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

RESULTS = Path(__file__).resolve().parents[2] / "docs" / "results"
COMMIT = re.compile(r"[0-9a-f]{40}")
# Tables still to be re-made from a clean commit. The test below fails once one of them is clean, so
# the list only shrinks; it is empty now.
PENDING: frozenset[str] = frozenset()
STUDIES = sorted(p.parent.name for p in RESULTS.glob("*/study.json"))


def _commits(name: str) -> tuple[str, list[str]]:
    meta = json.loads((RESULTS / name / "study.json").read_text())
    table = (RESULTS / name / "table.md").read_text() if (RESULTS / name / "table.md").exists() else ""
    return meta["commit"], re.findall(r"commit `([^`]*)`", table)


def test_there_are_results_to_check():
    assert len(STUDIES) >= 15 and PENDING <= set(STUDIES)


@pytest.mark.parametrize("name", STUDIES)
def test_a_committed_result_names_the_clean_commit_it_was_made_from(name):
    commit, in_table = _commits(name)
    assert all(c == commit for c in in_table), f"{name}: table.md names {in_table}, study.json {commit}"
    if name in PENDING:
        assert commit.endswith("+dirty"), f"{name} is clean now: remove it from PENDING"
        return
    assert COMMIT.fullmatch(commit), f"{name}: made from {commit!r}, not from a clean commit"


# -- numbers quoted by the pages ----------------------------------------------------------------------
DOCS = RESULTS.parent
NUMBER = re.compile(r"(?<![\w.])\d+\.\d+(?![\w.])")  # a decimal number, not part of a version or a name
# Sections whose quotes are derived from the table (ratios, percentages, rounded values) rather than
# copied: not checked yet. The test below fails once one of them quotes only the table's numbers.
DERIVED = frozenset({("reproducing.md", "generalisation-full"), ("reproducing.md", "drone-full"),
                     ("tutorial-dvbf.md", "dvbf-navigation-obs-full"), ("tutorial-dvbf.md", "dvbf-exploration-full"),
                     ("tutorial-dvbf.md", "dvbf-exploration-simple-large-full")})


def _held(*names: str) -> set[str]:
    """Every decimal number written in the tables of the result directories ``names``."""
    text = " ".join(p.read_text() for name in names for p in sorted((RESULTS / name).glob("*"))
                    if p.suffix in (".md", ".csv"))
    return set(re.findall(r"\d+\.\d+", text))


def _quotes() -> list[tuple[str, tuple[str, ...], str]]:
    """(where, result directories, text) for each passage that quotes a committed table: the sections
    of reproducing.md and tutorial-dvbf.md whose heading names ``docs/results/<dir>/``, the paragraphs
    of exploration.md that name one, and the measured section of drift-and-sensors.md."""
    found = []
    for page in ("reproducing.md", "tutorial-dvbf.md"):
        for section in re.split(r"^(?=#{2,4} )", (DOCS / page).read_text(), flags=re.MULTILINE):
            m = re.search(r"`docs/results/([\w-]+)/?`", section.splitlines()[0] if section else "")
            if m:
                found.append((f"{page}: {section.splitlines()[0]}", (m.group(1),), section))
    for i, para in enumerate(re.split(r"\n\s*\n", (DOCS / "exploration.md").read_text())):
        names = tuple(sorted(set(re.findall(r"docs/results/([\w-]+)", para))))
        if names:
            found.append((f"exploration.md paragraph {i}", names, para))
    drift = (DOCS / "drift-and-sensors.md").read_text().split("## Measured", 1)[1].split("\n## ", 1)[0]
    found.append(("drift-and-sensors.md: Measured", ("drift-full", "slip-full", "dropout-full"), drift))
    return found


QUOTES = _quotes()


def test_the_drift_exploration_and_slam_pages_are_checked():
    checked = {names for _, names, _ in QUOTES}
    assert {("drift-full", "slip-full", "dropout-full"), ("exploration-full",), ("exploration-reduced",),
            ("drift-full",), ("dvbf-slam-full",)} <= checked


@pytest.mark.parametrize("where, names, text", QUOTES, ids=[q[0][:60] for q in QUOTES])
def test_a_page_quotes_only_numbers_its_tables_hold(where, names, text):
    missing = sorted(set(NUMBER.findall(text)) - _held(*names))
    if (where.split(":")[0], names[0]) in DERIVED:
        assert missing, f"{where}: every number is in {names} now: remove it from DERIVED"
        return
    assert not missing, f"{where} quotes numbers that {', '.join(names)} do not hold: {missing}"

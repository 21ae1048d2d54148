"""The table of docs/errors.md is what the code prints, case by case, and no case is a traceback."""

import importlib.util
from pathlib import Path

DOCS = Path(__file__).resolve().parents[2] / "docs"


def _module():
    spec = importlib.util.spec_from_file_location("errors_table", DOCS / "errors_table.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_errors_page_lists_exactly_what_the_code_prints():
    mod = _module()
    generated = mod.table()
    assert "Traceback" not in generated
    rows = generated.splitlines()[2:]
    assert len(rows) == len(mod.CASES) >= 40
    assert all(row.rstrip().endswith("` |") and "``" not in row for row in rows)  # every case has a message
    assert generated == mod.page_table(), "docs/errors.md is stale: run python docs/errors_table.py"

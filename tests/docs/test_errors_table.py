"""The table of docs/errors.md is what the code prints, case by case, and no case is a traceback."""



def test_errors_page_lists_exactly_what_the_code_prints():
    import errors_table as mod
    generated = mod.table()
    assert "Traceback" not in generated
    rows = generated.splitlines()[2:]
    assert len(rows) == len(mod.CASES) >= 40
    assert all(row.rstrip().endswith("` |") and "``" not in row for row in rows)  # every case has a message
    assert generated == mod.page_table(), "docs/errors.md is stale: run python docs/errors_table.py"

"""Every python block of the tutorials runs, in order, in one namespace per page.

The Extending pages (docs/extending/) register schemes, terms, planners, rooms and encoders in
process-wide registries: each runs in its own interpreter so nothing it registers leaks into
the other tests.
"""

import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parents[2] / "docs"
# every page of the site with python blocks (the reproduced tables under results/ have none), but
# the extending pages (below)
PAGES = sorted(str(p.relative_to(DOCS)) for p in DOCS.rglob("*.md")
               if not {"results", "extending"} & set(p.relative_to(DOCS).parts) and "```python" in p.read_text())


# docs/extending/ stays out of PAGES (which run in this process): those pages register things in
# process-wide registries, so test_extending_page_runs gives each its own interpreter
EXTENDING = sorted(p.relative_to(DOCS).as_posix() for p in (DOCS / "extending").glob("*.md") if p.name != "index.md")


def blocks(page: str) -> list[str]:
    return re.findall(r"```python\n(.*?)```", (DOCS / page).read_text(), flags=re.S)


# runs the blocks of one page in order in one namespace; a failing block is named in the traceback
_RUNNER = """
import json, sys
page, code = sys.argv[1], json.loads(sys.stdin.read())
namespace = {"__name__": "__main__"}
for i, block in enumerate(code):
    exec(compile(block, f"{page}[block {i}]", "exec"), namespace)
"""


@pytest.mark.parametrize("page", PAGES)
def test_page_runs(page):
    code = blocks(page)
    assert code, f"{page} has no python blocks"
    namespace: dict = {}
    for i, block in enumerate(code):
        try:
            exec(compile(block, f"{page}[block {i}]", "exec"), namespace)
        except Exception as err:  # pragma: no cover - the message is the point
            raise AssertionError(f"{page} block {i} failed: {err!r}\n{block}") from err


def test_extending_pages_are_listed():
    assert EXTENDING == ["extending/efe-term.md", "extending/encoder.md", "extending/inference-scheme.md",
                         "extending/planner.md", "extending/world.md"]
    index = (DOCS / "extending" / "index.md").read_text()
    for page in EXTENDING:
        assert f"]({Path(page).name})" in index, f"extending/index.md does not link {page}"


@pytest.mark.parametrize("page", EXTENDING)
def test_extending_page_runs(page, tmp_path):
    code = blocks(page)
    assert code, f"{page} has no python blocks"
    proc = subprocess.run([sys.executable, "-c", _RUNNER, page], input=json.dumps(code), capture_output=True,
                          text=True, cwd=tmp_path, timeout=300)
    assert proc.returncode == 0, f"{page} failed:\n{proc.stderr[-4000:]}"


def test_every_linked_picture_and_page_exists():
    for page in [*DOCS.rglob("*.md"), DOCS.parent / "README.md"]:
        for target in re.findall(r"\]\(([^)#]+)\)", page.read_text()):
            if target.startswith("http"):
                continue
            assert (page.parent / target).exists(), f"{page.name} links to missing {target}"

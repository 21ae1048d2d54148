"""Every python block of the tutorials runs, in order, in one namespace per page."""

import re
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parents[2] / "docs"
# every page of the site with python blocks (the reproduced tables under results/ have none)
PAGES = sorted(str(p.relative_to(DOCS)) for p in DOCS.rglob("*.md")
               if "results" not in p.relative_to(DOCS).parts and "```python" in p.read_text())


def blocks(page: str) -> list[str]:
    return re.findall(r"```python\n(.*?)```", (DOCS / page).read_text(), flags=re.S)


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


def test_every_linked_picture_and_page_exists():
    for page in [*DOCS.rglob("*.md"), DOCS.parent / "README.md"]:
        for target in re.findall(r"\]\(([^)#]+)\)", page.read_text()):
            if target.startswith("http"):
                continue
            assert (page.parent / target).exists(), f"{page.name} links to missing {target}"

"""MkDocs hooks: the source tree mkdocstrings reads, and the API reference pages.

The libraries live in top-level folders (``genmodel/``, ``inference/``, ...) that install as
``cogmap.genmodel`` and so on (``[tool.setuptools.package-dir]``). mkdocstrings reads sources
statically by import path, so before the build :func:`build_tree` assembles ``.api/cogmap/`` as a
copy of ``cogmap/`` with each library folder copied in under its import name (links would be
resolved back to the real folders), and rewrites the reStructuredText roles of the docstrings
(``:func:`name```, ``:class:`~a.B```, a paragraph ending in ``::``) as Markdown code, since
mkdocstrings renders docstrings as Markdown. Nothing is imported.

The API pages are generated: one per package, one section per public module (every ``*.py`` not
starting with an underscore), so a new module is documented without editing a page.
"""

from __future__ import annotations

import re
import shutil
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LIBRARIES = ("genmodel", "inference", "planning", "envs")
# page name -> (title, package, folder of its modules)
API = {
    "genmodel": ("cogmap.genmodel", "cogmap.genmodel", "genmodel"),
    "inference": ("cogmap.inference", "cogmap.inference", "inference"),
    "planning": ("cogmap.planning", "cogmap.planning", "planning"),
    "envs": ("cogmap.envs", "cogmap.envs", "envs"),
    "agent": ("cogmap: agent loop, harness, runs, command line", "cogmap", "cogmap"),
    "aimapp": ("cogmap.agent (AIMAPP)", "cogmap.agent", "cogmap/agent"),
    "baselines": ("cogmap.baselines", "cogmap.baselines", "cogmap/baselines"),
    "drone": ("cogmap.drone", "cogmap.drone", "cogmap/drone"),
    "dvbf": ("cogmap.dvbf", "cogmap.dvbf", "cogmap/dvbf"),
    "fit": ("cogmap.fit", "cogmap.fit", "cogmap/fit"),
    "study": ("cogmap.study", "cogmap.study", "cogmap/study"),
}


ROLE = re.compile(r":(?:func|class|mod|meth|data|attr|obj|exc|const):`~?\.?([^`]+)`")
LITERAL = re.compile(r"(?<=[\w)`]):: *$", flags=re.M)


def markdown_roles(text: str) -> str:
    """``:func:`a.b``` -> ```a.b```, and a paragraph's closing ``::`` -> ``:``."""
    return LITERAL.sub(":", ROLE.sub(r"`\1`", text))


def build_tree(root: Path = ROOT) -> Path:
    """Create ``root/.api/cogmap`` (a copy of the sources under their import names) and return
    ``root/.api``."""
    api = root / ".api"
    if api.exists():
        shutil.rmtree(api)
    skip = shutil.ignore_patterns("__pycache__", "*.pyc")
    shutil.copytree(root / "cogmap", api / "cogmap", ignore=skip)
    for name in LIBRARIES:
        shutil.copytree(root / name, api / "cogmap" / name, ignore=skip)
    for path in api.rglob("*.py"):
        path.write_text(markdown_roles(path.read_text()))
    return api


def public_modules(folder: Path) -> list[str]:
    """Stems of the public modules of ``folder`` (no leading underscore, no ``__main__``)."""
    return sorted(p.stem for p in folder.glob("*.py") if not p.name.startswith("_"))


def api_page(title: str, package: str, folder: Path) -> str:
    """Markdown of one API page: the package docstring, then every public module."""
    lines = [f"# {title}", "", f"::: {package}", "    options:", "      members: false",
             "      show_root_heading: false", ""]
    for stem in public_modules(folder):
        lines += [f"::: {package}.{stem}", "    options:", "      heading_level: 2", ""]
    return "\n".join(lines)


# Built when MkDocs loads this hook, before the plugins are configured: mkdocstrings checks its
# search paths at that point and would fall back to the repository root (where ``cogmap/`` has no
# ``genmodel``) on a fresh clone. ``on_config`` rebuilds it for every build of ``mkdocs serve``.
build_tree()


def on_config(config, **kwargs):
    build_tree()
    return config


def on_files(files, config, **kwargs):
    from mkdocs.structure.files import File

    for name, (title, package, folder) in API.items():
        files.append(File.generated(config, f"api/{name}.md", content=api_page(title, package, ROOT / folder)))
    return files

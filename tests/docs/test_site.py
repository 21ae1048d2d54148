"""The documentation site builds strictly, its API reference lists every public name, and a
broken link fails the build (so the strict build guards the pages)."""

from __future__ import annotations

import importlib
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("mkdocs", reason="the docs extra (pip install -e .[docs]) is part of the test extra")

ROOT = Path(__file__).resolve().parents[2]
# packages whose exported names (``__all__``) the API reference must show
PACKAGES = ("cogmap.genmodel", "cogmap.inference", "cogmap.planning", "cogmap.envs", "cogmap.baselines",
            "cogmap.drone", "cogmap.study",
            "cogmap.fit")
# agent-layer modules whose public callables the reference must show
MODULES = ("cogmap.loop", "cogmap.harness", "cogmap.jax_agent")


def _mkdocs(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", *args], cwd=cwd,
                          capture_output=True, text=True, env={"NO_MKDOCS_2_WARNING": "1", "PATH": ""}, timeout=900)


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("site")
    shutil.rmtree(ROOT / ".api", ignore_errors=True)  # as on a fresh clone: the hook must build it in time
    done = _mkdocs("--site-dir", str(out), cwd=ROOT)
    assert done.returncode == 0, f"mkdocs build --strict failed:\n{done.stdout}\n{done.stderr}"
    return out


def public_names() -> list[str]:
    import inspect

    names = []
    for pkg in PACKAGES:
        mod = importlib.import_module(pkg)
        names += [f"{pkg}.{n}" for n in mod.__all__]
    for name in MODULES:
        mod = importlib.import_module(name)
        names += [f"{name}.{n}" for n, o in vars(mod).items()
                  if not n.startswith("_") and (inspect.isfunction(o) or inspect.isclass(o))
                  and o.__module__ == name]
    return names


def test_site_builds_strictly(site):
    assert (site / "index.html").exists()
    assert (site / "api" / "genmodel" / "index.html").exists()


def test_the_site_holds_no_build_caches(site):
    caches = [p for p in site.rglob("*") if p.name == "__pycache__" or p.suffix in (".pyc", ".py")]
    assert (site / "index.html").is_file() and not caches, caches[:5]


def test_every_public_name_is_in_the_api_reference(site):
    ids: set[str] = set()
    for page in (site / "api").rglob("index.html"):
        ids |= set(re.findall(r'id="(cogmap\.[\w.]+)"', page.read_text()))
    missing = []
    for full in public_names():
        pkg, name = full.rsplit(".", 1)
        # shown under the package, or under the module that defines it (a name that is also a
        # submodule's name is documented by its full path)
        if full not in ids and not any(i.startswith(pkg + ".") and i.endswith("." + name) for i in ids):
            missing.append(full)
    assert not missing, f"not in the API reference: {missing}"


def test_a_broken_link_fails_the_build(tmp_path):
    docs = tmp_path / "docs"
    docs.mkdir()
    (docs / "index.md").write_text("# Home\n\nSee [the missing page](missing.md).\n")
    config = f"INHERIT: {ROOT / 'mkdocs.yml'}\ndocs_dir: docs\nhooks: []\nnav:\n  - index.md\n"
    (tmp_path / "mkdocs.yml").write_text(config)
    done = _mkdocs("--site-dir", str(tmp_path / "site"), cwd=tmp_path)
    assert done.returncode != 0
    assert "missing.md" in done.stdout + done.stderr

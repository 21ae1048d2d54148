"""Run directories: config, seed, versions and commit recorded beside every result."""

from __future__ import annotations

import json
import platform
import subprocess
from importlib import metadata
from pathlib import Path

PACKAGES = ("cogmap", "numpy", "scipy", "jax", "networkx", "pybullet", "opencv-python-headless", "gymnasium", "ray")


def versions() -> dict[str, str]:
    out = {"python": platform.python_version()}
    for name in PACKAGES:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = "not installed"
    return out


def git_commit() -> str:
    root = Path(__file__).resolve().parents[1]
    try:
        res = subprocess.run(["git", "-C", str(root), "rev-parse", "HEAD"], capture_output=True, text=True,
                             timeout=5, check=False)
        commit = res.stdout.strip() or "unknown"
        dirty = subprocess.run(["git", "-C", str(root), "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, timeout=5, check=False).stdout.strip()
        return commit + ("+dirty" if dirty else "")
    except (OSError, subprocess.SubprocessError):
        return "unknown"


def write_manifest(out: Path, **fields) -> Path:
    """``run.json``: what ran, with which settings, on which code."""
    out.mkdir(parents=True, exist_ok=True)
    manifest = {**fields, "versions": versions(), "commit": git_commit()}
    path = out / "run.json"
    path.write_text(json.dumps(manifest, indent=1, default=_jsonable))
    return path


def _jsonable(x):
    try:
        import numpy as np

        if isinstance(x, np.generic):
            return x.item()
        if isinstance(x, np.ndarray):
            return x.tolist()
    except ImportError:  # pragma: no cover
        pass
    if isinstance(x, Path):
        return str(x)
    return repr(x)

"""docs/environments.md shows every registered id, with the spaces its environment declares today
and a picture; a new id, a changed space or a missing picture makes it stale."""

import importlib.util
from pathlib import Path

import cv2
import gymnasium as gym
import pytest

pytest.importorskip("pybullet")

DOCS = Path(__file__).resolve().parents[2] / "docs"


def _module():
    spec = importlib.util.spec_from_file_location("envs_gallery", DOCS / "envs_gallery.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_the_gallery_page_is_what_the_registered_environments_declare():
    mod = _module()
    ids = mod.registered_ids()
    assert len(ids) == 12 and all(i in gym.registry for i in ids)
    described = [mod.describe(i) for i in ids]
    assert all(d["observation"] and d["action"] for d in described)
    assert mod.PAGE.read_text() == mod.page(described), "docs/environments.md is stale: run python docs/envs_gallery.py"
    for i in ids:
        picture = cv2.imread(str(mod.IMG / f"{mod.slug(i)}.png"))
        assert picture is not None and picture.shape[0] >= 64 and picture.std() > 5, i  # an image, not blank

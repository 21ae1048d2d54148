"""docs/environments.md shows every registered id, with the spaces its environment declares today
and a picture; a new id, a changed space or a missing picture makes it stale."""

import cv2
import gymnasium as gym
import pytest

pytest.importorskip("pybullet")


def test_the_gallery_page_is_what_the_registered_environments_declare():
    import envs_gallery as mod
    ids = mod.registered_ids()
    assert len(ids) == 12 and all(i in gym.registry for i in ids)
    described = [mod.describe(i) for i in ids]
    assert all(d["observation"] and d["action"] for d in described)
    assert mod.PAGE.read_text() == mod.page(described), "docs/environments.md is stale: run python docs/envs_gallery.py"
    for i in ids:
        picture = cv2.imread(str(mod.IMG / f"{mod.slug(i)}.png"))
        assert picture is not None and picture.shape[0] >= 64 and picture.std() > 5, i  # an image, not blank

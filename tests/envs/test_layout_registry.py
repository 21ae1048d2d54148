"""A user's room by name: register_layout's clear errors, and every consumer finding the room."""

from __future__ import annotations

import json

import gymnasium as gym
import numpy as np
import pytest

from cogmap.envs import Box, Cylinder, Layout, make_layout, register_layout, unregister_layout
from cogmap.envs.layouts import LAYOUTS
from cogmap.envs.registry import LAYOUT_IDS
from cogmap.explore import layout_name


def closet(seed: int = 0) -> Layout:
    """A 3 x 3 m room with one pillar (walls 0.1 m thick)."""
    walls = (Box("wall_s", 1.5, -0.05, 3.2, 0.1, 2.0), Box("wall_n", 1.5, 3.05, 3.2, 0.1, 2.0),
             Box("wall_w", -0.05, 1.5, 0.1, 3.0, 2.0), Box("wall_e", 3.05, 1.5, 0.1, 3.0, 2.0))
    pillar = Cylinder("pillar", 2.2 + 0.1 * seed, 2.2, 0.25, 1.0, (0.8, 0.2, 0.2))
    return Layout("closet", (-0.1, -0.1, 3.1, 3.1), (*walls, pillar), ((0.8, 0.8, 0.0),))


UNREGISTER = unregister_layout  # what the suite's ``registered`` fixture removes with


def test_register_layout_errors(registered):
    with pytest.raises(ValueError, match="non-empty string"):
        register_layout("", closet)
    with pytest.raises(TypeError, match="expected a callable factory"):
        register_layout("closet", closet(0))
    with pytest.raises(ValueError, match="built-in layout"):
        register_layout("house", closet)
    with pytest.raises(ValueError, match="returned dict, not a Layout"):
        register_layout("closet", lambda seed=0: {})
    assert "closet" not in LAYOUTS  # nothing half-registered
    with pytest.raises(ValueError, match="Gymnasium id 'cogmap/House-v0'|built-in environment id"):
        register_layout("closet", closet, env_id="cogmap/House-v0")
    with pytest.raises(ValueError, match="Gymnasium id 'CartPole-v1' is taken"):
        register_layout("closet", closet, env_id="CartPole-v1")
    register_layout("closet", closet, env_id="test/Closet-v0")
    registered.append("closet")
    with pytest.raises(ValueError, match="exists.*overwrite=True"):
        register_layout("closet", closet)
    register_layout("closet", closet, env_id="test/Closet-v0", overwrite=True)
    with pytest.raises(ValueError, match="built-in layout"):
        unregister_layout("house")
    with pytest.raises(KeyError, match="no registered layout named 'nope'.*closet"):
        unregister_layout("nope")
    with pytest.raises(KeyError, match="unknown layout 'nope'.*closet"):
        make_layout("nope")


def test_unregister_removes_the_room_and_its_id():
    register_layout("closet", closet, env_id="test/Closet-v0")
    unregister_layout("closet")
    assert "closet" not in LAYOUTS and "test/Closet-v0" not in LAYOUT_IDS and "test/Closet-v0" not in gym.registry
    with pytest.raises(ValueError, match="unknown environment 'closet'"):
        layout_name("closet")


def test_every_consumer_finds_a_registered_room(registered):
    register_layout("closet", closet, env_id="test/Closet-v0")
    registered.append("closet")
    assert make_layout("closet", seed=1).shape("pillar").x == pytest.approx(2.3)
    assert layout_name("closet") == "closet" and layout_name("test/Closet-v0") == "closet"
    env = gym.make("test/Closet-v0")
    try:
        env.reset(seed=0)
        assert env.unwrapped.sim.layout.name == "closet"
        assert env.spec.max_episode_steps == 500
        obs, *_ = env.step(env.action_space.n - 1)  # stay
        np.testing.assert_allclose(obs["odometry"][:2], [0.8, 0.8], atol=1e-4)
    finally:
        env.close()


def test_cli_plugin_module_registers_a_room_for_explore(registered, tmp_path, monkeypatch, capsys):
    from cogmap.cli import main

    (tmp_path / "closet_plugin.py").write_text(
        "from cogmap.envs import register_layout\n"
        "from test_layout_registry_room import closet\n"
        "register_layout('closet', closet)\n")
    (tmp_path / "test_layout_registry_room.py").write_text(
        "from cogmap.envs import Box, Cylinder, Layout\n\n" + _source(closet))
    monkeypatch.syspath_prepend(str(tmp_path))
    registered.append("closet")
    out = tmp_path / "run"
    code = main(["--plugin", "closet_plugin", "explore", "--env", "closet", "--steps", "3", "--out", str(out),
                 "--quiet"])
    assert code == 0, capsys.readouterr().err
    manifest = json.loads((out / "run.json").read_text())
    assert manifest["env"] == "closet"
    assert json.loads((out / "metrics.json").read_text())["steps"] == 3


def test_cli_plugin_that_cannot_be_imported_is_a_one_line_error(capsys):
    from cogmap.cli import main

    assert main(["--plugin", "no_such_plugin_module", "explore", "--steps", "1"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "No module named 'no_such_plugin_module'" in err


def _source(fn) -> str:
    import inspect

    return inspect.getsource(fn)

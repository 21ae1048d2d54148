"""The procedural building family: every kind is closed, connected through 1.6 m passages, holds
at least five distinct free starts and a free area in its stated range; seeded; reachable from
make_layout, the gym registry and the command line; the agent explores one."""

from __future__ import annotations

import sys
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

from cogmap.envs.buildings import AREA_RANGE, KINDS, MIN_STARTS, building
from cogmap.envs.geometry import ShapeSet
from cogmap.envs.layouts import make_layout
from cogmap.envs.occupancy import layout_grid
from cogmap.envs.robot import ROBOT_RADIUS

sys.path.insert(0, str(Path(__file__).resolve().parent))
from test_passages import assert_connected  # noqa: E402  (the shipped layouts' 1.6 m passage check)


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("seed", [0, 2])
def test_every_kind_is_connected_with_distinct_free_starts(kind, seed):
    lay = building(seed, kind)
    grid = layout_grid(lay)
    starts = np.array([s[:2] for s in lay.starts])
    assert len(starts) >= MIN_STARTS
    d = np.hypot(*(starts[:, None] - starts[None]).transpose(2, 0, 1))
    assert d[np.triu_indices(len(starts), 1)].min() >= 1.0  # distinct
    assert (ShapeSet(lay.shapes).distance(starts) > ROBOT_RADIUS + 0.1).all()  # free, with room for the robot
    reach = grid.reachable(starts[0])
    rc = grid.world_to_cell(starts)
    assert reach[rc[:, 0], rc[:, 1]].all()  # one free region holds every start ...
    assert not (reach[0].any() or reach[-1].any() or reach[:, 0].any() or reach[:, -1].any())  # ... closed
    lo, hi = AREA_RANGE[kind]
    assert lo <= grid.free_area(starts[0]) <= hi
    assert_connected(lay, starts)  # every start reached through passages >= 1.6 m wide
    assert len(set(lay.names)) == len(lay.names)


def test_buildings_are_seeded_and_registered():
    a = building(4, "T")
    assert a == building(4, "T") and a != building(5, "T") and a != building(4, "U")
    assert make_layout("building", seed=4, kind="T") == a
    assert make_layout("building", seed=2) == building(2, "office")
    env = gym.make("cogmap/Building-v0", layout_seed=4, layout_kwargs={"kind": "T"})
    try:
        assert env.unwrapped.sim.layout == a
        obs, _ = env.reset(seed=0)
        assert env.observation_space.contains(obs)
    finally:
        env.close()
    with pytest.raises(ValueError, match="unknown building kind 'V'"):
        building(0, "V")


def test_an_aimapp_run_in_an_l_building_explores(tmp_path):
    from cogmap.explore import explore

    m = explore("building:L:3", steps=15, seed=0, out=tmp_path / "run", progress=False, patience=0)
    assert m["steps"] == 15 and m["distance_m"] > 8 and m["num_states"] >= 8
    assert m["coverage"] > 0.2 and m["failed_moves"] <= 3

"""The pose grid hash against a brute-force scan of every pose."""

from __future__ import annotations

import numpy as np
import pytest

from cogmap.agent.aimapp import initial_model
from cogmap.agent.config import AgentConfig
from cogmap.genmodel.spatial import PoseIndex


@pytest.mark.parametrize("seed", range(3))
def test_near_and_nearest_match_brute_force(seed):
    rng = np.random.default_rng(seed)
    # a lattice (many exact ties) plus scattered points, some far away
    lattice = np.stack(np.meshgrid(np.arange(12.0), np.arange(9.0)), axis=-1).reshape(-1, 2)
    poses = np.vstack([lattice, rng.uniform(-20, 30, size=(60, 2))])
    rng.shuffle(poses)
    index = PoseIndex(poses, cell=1.0, count=len(poses))
    for xy in np.vstack([rng.uniform(-30, 40, size=(80, 2)), lattice[:10] + 0.5]):
        d_all = np.hypot(*(poses - xy).T)
        for r in (0.5, 1.5, 3.0):
            idx, d = index.near(xy, r)
            np.testing.assert_array_equal(idx, np.flatnonzero(d_all <= r))
            np.testing.assert_allclose(d, d_all[idx])
        i, d = index.nearest(xy)
        assert i == int(np.argmin(d_all)) and d == pytest.approx(d_all.min())


def test_index_follows_model_growth_and_reallocation():
    cfg = AgentConfig(influence_radius=1.0, initial_capacity=2)
    model = initial_model(cfg, np.zeros(2))
    index = model.pose_index()
    rng = np.random.default_rng(0)
    for _ in range(300):  # capacity doubles several times
        model.add_state(0, pose=rng.uniform(-10, 10, size=2), obs_count=0.1)
    assert model.pose_index() is index  # kept up to date, not rebuilt
    poses = model.pose.poses[: model.num_states[0]]
    for xy in rng.uniform(-12, 12, size=(30, 2)):
        d_all = np.hypot(*(poses - xy).T)
        assert index.nearest(xy)[0] == int(np.argmin(d_all))


def test_empty_index_and_bad_cell():
    index = PoseIndex(np.zeros((4, 2)), cell=1.0)
    assert index.nearest((0.0, 0.0)) == (-1, np.inf)
    assert index.near((0.0, 0.0), 5.0)[0].size == 0
    with pytest.raises(ValueError, match="positive"):
        PoseIndex(np.zeros((1, 2)), cell=0.0)

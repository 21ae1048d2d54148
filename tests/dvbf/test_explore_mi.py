"""The DVBF-LM exploration agent against the random walk on seeded runs in pybullet mazes.

Measured with this test's light emission pretraining (300 steps, 100 Adam steps) and the study's MI
settings, 300 steps in moderate / small mazes, in float32 as the studies and the command line run: tile
ratio 0.444 vs the random walk's 0.278 (study seed 0, maze 1) and 0.361 vs 0.194 (seed 1, maze 2); the MI
agent was never stopped by a wall (the random walk 36 and 41 times). One run is sensitive to rounding
(seed 1 in float64 ended at 0.167 vs 0.194), so the test runs both seeds in float32 and asserts on their
mean ratio; per seed it asserts that the agent stays localised, keeps off the walls and that its map
gains information.
"""

import numpy as np
import pytest

from cogmap.dvbf.explore import STUDY_MI, ExploreConfig, explore, pretrained_emission
from cogmap.envs.maze import make_maze


@pytest.mark.heavy
def test_mi_agent_explores_more_than_the_random_walk_and_stays_localised(tmp_path, float32):
    # a small emission pretraining keeps the test short; the study uses 2,000 steps and 1,500 Adam steps
    emission = pretrained_emission(tmp_path, steps=300, iters=100)
    ratios = {"mi": [], "random": []}
    for seed in (0, 1):
        maze = make_maze(seed + 1, "moderate", "small")
        mi = explore(maze, 300, ExploreConfig(method="mi", mi=STUDY_MI, train_iters=2, seed=seed), emission=emission)
        rw = explore(maze, 300, ExploreConfig(method="random", seed=seed))
        assert np.allclose(mi.poses[0], rw.poses[0])
        ratios["mi"].append(mi.ratio_curve[-1][1])
        ratios["random"].append(rw.ratio_curve[-1][1])
        err = np.hypot(*(mi.estimates[:, :2] - mi.poses[:, :2]).T)
        assert err.max() < 0.08  # corridors are 1/12 = 0.083 wide
        assert mi.blocked < rw.blocked / 2
        assert mi.info_curve[-1][1] > mi.info_curve[0][1] + 1.0  # KL(q(M) || p(M)) grows from 0
        assert len(mi.plan_seconds) >= 300 // 50
    assert np.mean(ratios["mi"]) > np.mean(ratios["random"]) + 0.05

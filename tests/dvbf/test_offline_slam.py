"""Offline SLAM (paper Appendix B-I): seeded behaviour in a LiDAR maze against path integration, the
round schedule, and bad settings."""

import numpy as np
import pytest

from cogmap.envs.maze import make_maze
from cogmap.envs.maze_sim import ActuationNoise
from cogmap.envs.maze_traversal import traverse
from cogmap.genmodel.dvbf import DVBFConfig
from cogmap.inference.offline_slam import OfflineConfig, offline_slam
from cogmap.inference.online_slam import path_integration, pretrain_emission


@pytest.mark.heavy
def test_offline_slam_beats_path_integration():
    maze = make_maze(5, "simple", "medium")  # 0.5 x 0.5, 12 x 12 map
    cfg = DVBFConfig(extent=maze.size, map_side=maze.map_side, hidden=32, sigma_t=(0.0005, 0.0005, 0.02))
    first = traverse(make_maze(4, "simple", "medium"), 600, seed=0, step=0.006)  # another maze, known poses
    emission, _ = pretrain_emission(first.poses, first.scans, cfg, iters=300, seed=0)
    test = traverse(maze, 400, seed=1, step=0.006, noise=ActuationNoise(rot_std=0.02, trans_frac=0.1))
    config = OfflineConfig(model=cfg, n_particles=200, rounds=3, train_iters=150, batch=32, grow=True,
                           freeze_emission=True, seed=0)
    rounds = []
    res = offline_slam(test.scans, test.controls, test.poses[0], config, emission=emission, round_estimates=rounds)
    err = np.hypot(*(res.estimates[:, :2] - test.poses[:, :2]).T)
    pi = path_integration(test.poses[0], test.controls)
    err_pi = np.hypot(*(pi[:, :2] - test.poses[:, :2]).T)
    assert err_pi[-1] > 0.03  # the noisy controls drift
    assert err[-1] < 0.5 * err_pi[-1]
    assert err.mean() < 0.5 * err_pi.mean()
    assert len(rounds) == 3 and np.array_equal(rounds[-1], res.estimates)
    assert len(res.losses) == 3 * 150 and np.allclose(res.estimates[0], test.poses[0])


def test_bad_settings_and_input_are_refused():
    with pytest.raises(ValueError, match="sizes must be >= 1"):
        OfflineConfig(chunk=0)
    with pytest.raises(ValueError, match="jitter >= 0"):
        OfflineConfig(jitter=-0.1)
    with pytest.raises(ValueError, match="need T - 1"):
        offline_slam(np.zeros((5, 20)), np.zeros((5, 2)), [0.5, 0.5, 0.0], OfflineConfig(rounds=1, train_iters=0))

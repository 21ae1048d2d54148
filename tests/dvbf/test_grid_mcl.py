"""Occupancy-grid LiDAR model and Monte Carlo localisation (the Cartographer stand-in of dvbf-slam)."""

import numpy as np
import pytest

from cogmap.envs.maze import make_maze
from cogmap.envs.maze_sim import LIDAR_RANGE, N_BEAMS, MazeSim
from cogmap.envs.maze_traversal import traverse
from cogmap.genmodel.occupancy_lidar import beam_log_likelihood, expected_ranges, march_samples
from cogmap.inference.grid_mcl import MCLConfig, mcl_localise


def test_ray_march_against_hand_computed_ranges():
    # a 10 x 10 raster over [0, 1]^2, one occupied column at x in [0.7, 0.8)
    occ = np.zeros((10, 10), bool)
    occ[7, :] = True
    r = np.asarray(expected_ranges(occ, 1.0, np.array([[0.25, 0.55, 0.0]]), 4, 0.6, 0.001))[0]
    # east: the column starts at 0.7 (0.45 away); north: nothing within 0.6 inside (0.45 to the edge,
    # and outside counts as wall); west: the edge at 0.25; south: nothing within 0.6 -> the edge at 0.55
    assert r == pytest.approx([0.45, 0.45, 0.25, 0.55], abs=1.5e-3)
    far = np.asarray(expected_ranges(np.zeros((10, 10), bool), 4.0, np.array([[2.0, 2.0, 0.3]]), 8, 0.5, 0.01))
    assert np.allclose(far, 0.5)  # nothing met: the maximum range


def test_ray_march_matches_the_pybullet_lidar_in_a_maze():
    maze = make_maze(1)
    rng = np.random.default_rng(0)
    with MazeSim(maze) as sim:
        poses = np.array([[*maze.cell_centre(*rng.integers(maze.n, size=2)), rng.uniform(-np.pi, np.pi)]
                          for _ in range(10)])
        true = np.array([sim.lidar(p) for p in poses])
    grid = np.asarray(expected_ranges(maze.occupancy(200), maze.size, poses, N_BEAMS, LIDAR_RANGE, 0.0025))
    assert np.median(np.abs(grid - true)) < 0.006  # raster of 0.005 and walls 0.006 thick


def test_beam_likelihood_against_the_closed_form():
    exp_r = np.array([[0.2, 0.5], [0.3, 0.1]])
    obs = np.array([0.25, 0.5])
    sigma, floor, rmax = 0.05, 0.1, 0.53
    got = np.asarray(beam_log_likelihood(exp_r, obs, sigma, floor, rmax))
    gauss = np.exp(-0.5 * ((obs - exp_r) / sigma) ** 2) / (sigma * np.sqrt(2 * np.pi))
    assert got == pytest.approx(np.log((1 - floor) * gauss + floor / rmax).sum(1), rel=1e-5)  # float32


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="step > 0"):
        march_samples(0.5, 0.0)
    with pytest.raises(ValueError, match="sigma > 0"):
        MCLConfig(sigma=0.0)
    with pytest.raises(ValueError, match="controls"):
        mcl_localise(np.zeros((200, 200), bool), 1.0, np.zeros(3), np.zeros((5, 2)), np.zeros((5, 20)), MCLConfig(),
                     0.53)


def test_mcl_on_the_true_map_beats_path_integration_on_a_traversal():
    from cogmap.envs.maze_sim import ROBOT_NOISE
    from cogmap.inference.online_slam import path_integration

    maze = make_maze(2)
    tr = traverse(maze, 600, seed=3, noise=ROBOT_NOISE)
    means, stds, parts = mcl_localise(maze.occupancy(200), maze.size, tr.poses[0], tr.controls, tr.scans,
                                      MCLConfig(n_particles=200, seed=1), LIDAR_RANGE)
    err = np.hypot(*(means[:, :2] - tr.poses[:, :2]).T)
    pi = path_integration(tr.poses[0], tr.controls)
    err_pi = np.hypot(*(pi[:, :2] - tr.poses[:, :2]).T)
    assert means.shape == (600, 3) and stds.shape == (600, 2) and parts.shape == (200, 3)
    assert err.max() < 0.02 and err[-1] < err_pi[-1]

"""Exploration by mutual information (planning.mi_exploration): obstacle penalty, candidates, MI score."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from cogmap.genmodel.dvbf import DVBFConfig, Emission
from cogmap.genmodel.latent_map import MapPosterior
from cogmap.planning.mi_exploration import (
    MIConfig,
    beam_endpoints,
    candidate_controls,
    mean_paths,
    obstacle_penalty_grid,
    penalty_at,
    projected_mutual_information,
    rollout,
    scan_free_steps,
    score_candidates,
    squash_controls,
    truncate_at_collision,
)


def test_beam_endpoints_by_hand():
    # 4 beams at heading pi/2: beam k points at pi/2 + k pi/2; the third (length 0.53) hits nothing
    pts = beam_endpoints([[0.5, 0.5, np.pi / 2]], [[0.1, 0.2, 0.53, 0.3]], lidar_range=0.53)
    assert np.allclose(pts, [[0.5, 0.6], [0.3, 0.5], [0.8, 0.5]], atol=1e-12)


def test_penalty_zero_in_free_space_and_high_at_end_points():
    grid = obstacle_penalty_grid([[0.55, 0.55]] * 10, 40, extent=1.0, side=10)
    assert grid[5, 5] == pytest.approx(np.log(0.25 + 1e-4) - np.log(1e-4))
    assert np.count_nonzero(grid) == 1
    # bilinear read: full value at the cell centre, half way between it and a free centre
    vals = np.asarray(penalty_at(grid, jnp.array([[0.55, 0.55], [0.6, 0.55], [0.15, 0.15]]), 1.0))
    assert np.allclose(vals, [grid[5, 5], grid[5, 5] / 2, 0.0], atol=1e-5)
    with pytest.raises(ValueError, match="side"):
        obstacle_penalty_grid([[0.1, 0.1]], 1, 1.0, 1)


def test_rollout_and_control_bounds():
    u = squash_controls(jnp.array([[10.0, 10.0], [10.0, -10.0], [-10.0, 0.0]]), max_turn=0.3, max_step=0.01)
    assert np.allclose(u[:, 0], [np.pi, 0.3, -0.3], atol=1e-6)  # the first turn may be anything
    assert np.allclose(u[:, 1], [0.01, 0.0, 0.005], atol=1e-6)
    z = rollout(jnp.array([0.5, 0.5, 0.0]), jnp.array([[np.pi / 2, 0.1], [np.pi / 2, 0.2]]))
    assert np.allclose(z[-1, :2], [0.3, 0.6], atol=1e-6) and abs(np.cos(z[-1, 2]) + 1) < 1e-6


def test_obstacle_penalty_pushes_candidates_away_from_a_wall():
    # a known wall along x = 0.5; the agent stands 0.15 in front of it, facing it
    wall = np.stack([np.full(200, 0.5), np.linspace(0, 1, 200)], 1)
    grid = obstacle_penalty_grid(wall, 200, 1.0, 50)
    cfg = MIConfig(horizon=30, n_candidates=16, opt_iters=200, pose_samples=2)
    start = np.array([[0.35, 0.5, 0.0]])
    c = candidate_controls(jax.random.PRNGKey(0), start, grid, 1.0, cfg)

    def crossing(controls):
        paths = np.array([np.asarray(rollout(jnp.asarray(start[0]), jnp.asarray(u))) for u in controls])
        return int((paths[:, :, 0].max(1) > 0.5).sum())

    assert c.penalty.mean() < 0.6 * c.penalty_initial.mean()
    assert crossing(c.controls) < crossing(c.initial)  # fewer candidates cross the wall
    assert np.all(c.controls[..., 1] >= 0) and np.all(np.abs(c.controls[:, 1:, 0]) <= 0.35 + 1e-6)


def _half_known_model():
    """A 2 x 2 world whose map is known (std e-6) for x < 1 and at the prior for x > 1."""
    model = DVBFConfig(extent=2.0, map_side=8, hidden=32, depth=2, sigma_t=(0.0005, 0.0005, 0.002), sigma_e=0.02)
    emission = Emission(model, jax.random.PRNGKey(0))
    mean = jax.random.normal(jax.random.PRNGKey(1), (8, 8, 20))
    known = ((jnp.arange(8) + 0.5) * 2 / 8 < 1.0)[:, None, None]
    q = MapPosterior(jnp.where(known, mean, 0.0), jnp.where(known, -6.0, 0.0) * jnp.ones((8, 8, 20)))
    return model, emission, q


@pytest.mark.heavy
def test_looking_at_uncertain_cells_scores_higher():
    model, emission, q = _half_known_model()
    cfg = MIConfig(horizon=10, n_candidates=1, n_marginal=40, n_maps=8, n_per_map=20, obs_every=5)
    u = np.tile([[0.0, 0.01]], (10, 1))[None]  # straight ahead, north
    # beams reach 0.53: from x = 0.3 they see only known cells, from x = 1.7 only unknown ones
    known = [score_candidates(jax.random.PRNGKey(s), q, emission, model, [[0.3, 0.8, np.pi / 2]], u, cfg)[0]
             for s in range(3)]
    unknown = [score_candidates(jax.random.PRNGKey(s), q, emission, model, [[1.7, 0.8, np.pi / 2]], u, cfg)[0]
               for s in range(3)]
    assert np.mean(unknown) > np.mean(known) + 0.8
    assert abs(np.mean(known)) < 0.5


def test_projected_mi_of_a_known_gaussian_channel():
    # x = m + noise in 3 dims with var(m) = 1, var(noise) = 0.25: I = 1.5 log 5 = 2.41 nats
    rng = np.random.default_rng(0)
    m = rng.normal(size=(40, 1, 3))
    cond = m + rng.normal(0, 0.5, (40, 200, 3))
    marg = rng.normal(size=(3000, 3)) + rng.normal(0, 0.5, (3000, 3))
    assert projected_mutual_information(marg, cond, dim=3) == pytest.approx(1.5 * np.log(5), abs=0.2)
    with pytest.raises(ValueError, match="conditionals"):
        projected_mutual_information(marg, cond[0], dim=3)


def test_candidates_are_cut_at_their_first_predicted_collision():
    wall = np.stack([np.full(200, 0.5), np.linspace(0, 1, 200)], 1)
    grid = obstacle_penalty_grid(wall, 200, 1.0, 50)
    east = np.tile([[0.0, 0.01]], (40, 1))
    north = east.copy()
    north[0, 0] = np.pi / 2
    cut, free = truncate_at_collision(np.stack([east, north]), np.array([0.3, 0.5, 0.0]), grid, 1.0)
    # heading east: 19 steps reach x = 0.49, the last pose before the wall's cell (bins of 0.02, read
    # bilinearly between cell centres); the 20th would stand on the wall
    assert free[0] == 19 and free[1] == 40
    assert np.all(cut[0, free[0]:, 1] == 0) and np.all(cut[0, :free[0], 1] == 0.01)
    assert np.array_equal(cut[1], north) and np.array_equal(cut[:, :, 0], np.stack([east, north])[:, :, 0])


def test_a_start_beside_a_wall_does_not_cut_every_candidate():
    # end points at x = 0.5 fill the histogram column [0.5, 0.52) (centre 0.51); the agent stands at
    # x = 0.495, a quarter of the way up that column's bilinear ramp (0.49 to 0.51), where the penalty is above
    # the level: walking away or along the wall is free, walking into it is cut
    wall = np.stack([np.full(200, 0.5), np.linspace(0, 1, 200)], 1)
    grid = obstacle_penalty_grid(wall, 200, 1.0, 50)
    start = np.array([0.495, 0.5, 0.0])
    assert float(penalty_at(grid, jnp.asarray(start[None, :2]), 1.0)[0]) > 0.5
    west = np.tile([[0.0, 0.01]], (20, 1))
    west[0, 0] = np.pi
    north = np.tile([[0.0, 0.01]], (20, 1))
    north[0, 0] = np.pi / 2
    east = np.tile([[0.0, 0.01]], (20, 1))
    _, free = truncate_at_collision(np.stack([west, north, east]), start, grid, 1.0)
    assert free[0] == 20 and free[1] == 20 and free[2] < 3


def test_candidates_stop_before_a_wall_the_current_scan_shows():
    # 4 beams from heading 0: a wall 0.1 ahead (east), nothing within range elsewhere
    scan = np.array([0.1, 0.53, 0.53, 0.53])
    east = np.tile([[0.0, 0.01]], (20, 1))
    north_west = east.copy()
    north_west[0, 0] = 3 * np.pi / 4  # between beams 1 and 2, both without a return
    paths = mean_paths(np.stack([east, north_west]), np.array([0.5, 0.5, 0.0]))
    free = scan_free_steps(paths, scan, 0.53, margin=0.015)
    # step k ends 0.01 (k + 1) east; blocked once 0.01 (k + 1) + 0.015 > 0.1, i.e. from k = 8 on
    assert free.tolist() == [8, 20]
    with pytest.raises(ValueError, match="scan_margin"):
        MIConfig(scan_margin=-1.0)

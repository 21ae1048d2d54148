"""Baselines in the pybullet rooms (short runs)."""

import numpy as np
import pytest

from cogmap.baselines import FrontierConfig, FrontierExplorer, OdomMap, OracleConfig, OracleTour, RandomWalk, run_policy
from cogmap.baselines.gridnav import extract_path, line_free, shortest_paths
from cogmap.explore import default_config, episode_metrics, make_sim

FRONTIER_STEP_BUDGET = 40  # decisions of 1 m at most


def test_shortest_paths_go_around_a_wall():
    b = np.zeros((5, 5), bool)
    b[0:4, 2] = True
    dist, pred = shortest_paths(b, (0, 0))
    path = extract_path(pred, b.shape, (0, 4))
    assert path[0] == (0, 0) and path[-1] == (0, 4)
    assert all(not b[p] for p in path)
    assert dist[0, 4] == pytest.approx(8 + 2 * np.sqrt(2))  # no diagonal may cut the wall end
    assert not line_free(b, (0, 0), (0, 4)) and line_free(b, (4, 0), (4, 4))


def test_odom_map_fills_a_scan_and_marks_hits():
    m = OdomMap((0.0, 0.0), 10.0, 0.05)
    angles = np.linspace(0, 2 * np.pi, 360, endpoint=False)
    m.integrate(np.zeros(3), np.full(360, 2.0), angles, max_range=12.0)
    assert m.seen.sum() * 0.05**2 == pytest.approx(np.pi * 4, rel=0.08)
    assert m.occ.sum() > 100


def _run(env, policy, seed, steps):
    cfg = default_config(env)
    sim = make_sim(env, cfg, seed)
    try:
        ep = run_policy(sim, policy, steps, stop_coverage=None)
        return episode_metrics(sim, ep), ep
    finally:
        sim.close()


@pytest.mark.parametrize("seed", [0, 1])
def test_frontier_exploration_covers_the_mini_warehouse(seed):
    pol = FrontierExplorer(FrontierConfig(step_length=1.0))
    m, ep = _run("mini_warehouse", pol, seed, FRONTIER_STEP_BUDGET)
    assert m["coverage"] >= 0.95
    assert pol.done, "frontier exploration should finish (no frontier left) within the budget"
    assert m["steps"] < FRONTIER_STEP_BUDGET


def test_frontier_finishes_the_small_warehouse():
    pol = FrontierExplorer(FrontierConfig(step_length=1.0))
    m, _ = _run("small_warehouse", pol, 0, 60)
    assert m["coverage"] >= 0.95 and pol.done


def test_oracle_and_random_walk_run_with_the_same_episode_rows():
    m, ep = _run("mini_warehouse", OracleTour(OracleConfig(step_length=1.0)), 0, 30)
    assert m["coverage"] >= 0.95 and m["failed_moves"] == 0
    m2, ep2 = _run("mini_warehouse", RandomWalk(1.0, seed=3), 0, 15)
    assert set(ep2.rows[0]) == set(ep.rows[0])
    assert 0 < m2["coverage"] <= 1.0 and m2["steps"] == 15
    m3, _ = _run("mini_warehouse", RandomWalk(1.0, seed=3), 0, 15)
    assert m3 == {**m2, "decision_ms_mean": m3["decision_ms_mean"], "decision_ms_p95": m3["decision_ms_p95"]}

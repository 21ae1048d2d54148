"""Exploration efficiency in the pybullet house: coverage efficiency at 90 % coverage.

CE@90 = area covered / distance travelled, both read when LiDAR coverage first reaches 90 %
(``bench/exploration.py`` computes it the same way over every layout and 5 seeds).
Measured on seeds 0 and 2 (``python bench/exploration.py --envs house``): before the sensed-grid
terms 1.86 and 2.07 m2/m (mean 1.97), with them 2.63 and 3.12 (mean 2.88); the oracle tour
reaches 3.89 and 3.78. The threshold 2.3 lies between the two means (0.3 above the old one,
0.6 below the new one), so the test fails if the agent falls back to visiting the map node by
node.
"""

from __future__ import annotations

import numpy as np

from cogmap.agent.aimapp import AIMAPPAgent
from cogmap.explore import coverage_tracker, default_config, make_sim, run_agent

THRESHOLD = 2.3


def _ce_at_90(env: str, seed: int, steps: int) -> tuple[float | None, float]:
    cfg = default_config(env)
    sim = make_sim(env, cfg, seed)
    try:
        agent = AIMAPPAgent(cfg, seed=seed)
        tracker = coverage_tracker(sim)
        ep = run_agent(sim, agent, steps, progress=False, stop=lambda d: tracker.coverage >= 0.9)
        free = tracker.total * sim.grid.resolution**2
        cov = np.asarray(ep.coverage)
        hit = np.flatnonzero(cov >= 0.9)
        if hit.size == 0:
            return None, float(cov[-1])
        i = int(hit[0])
        return float(cov[i] * free / ep.distance[i]), float(cov[i])
    finally:
        sim.close()


def test_house_exploration_reaches_90_percent_efficiently():
    results = [_ce_at_90("house", seed, 200) for seed in (0, 2)]
    assert all(ce is not None and cov >= 0.9 for ce, cov in results), results
    assert np.mean([ce for ce, _ in results]) >= THRESHOLD, results


def test_exploration_page_python_blocks_run():
    import re
    from pathlib import Path

    page = Path(__file__).resolve().parents[2] / "docs" / "exploration.md"
    code = re.findall(r"```python\n(.*?)```", page.read_text(), flags=re.S)
    assert code
    namespace: dict = {}
    for i, block in enumerate(code):
        exec(compile(block, f"exploration.md[block {i}]", "exec"), namespace)
    assert namespace["objective"].names == ("sensed_info_gain", "inductive", "collision")
    near, far = namespace["sg"].unseen_area(namespace["grid"], [[0.0, 0.0], [0.0, -3.0]])
    assert near < far


class _RigidAgent:
    """Stands in for the agent's pose helper: belief = rotation by ``theta`` then a shift."""

    def __init__(self, theta, shift):
        c, s = np.cos(theta), np.sin(theta)
        self.R, self.t = np.array([[c, -s], [s, c]]), np.asarray(shift, dtype=float)

    def believed_pose(self, odometry):
        return self.R @ np.asarray(odometry, dtype=float)[:2] + self.t


def test_scan_goes_through_the_agents_pose_mapping_even_when_it_rotates():
    from cogmap.agent.aimapp import Sensed
    from cogmap.agent.config import AgentConfig
    from cogmap.agent.viewmap import ViewMap
    from cogmap.inference.se2 import SE2
    from cogmap.planning import sensed as sg

    agent = _RigidAgent(np.pi / 2, (5.0, -1.0))
    views = ViewMap(AgentConfig())
    odom = np.array([1.0, 2.0, 0.3])
    scan = np.array([[2.0, 0.0], [0.0, -1.5]])  # returns relative to the robot, odometry frame
    views.observe(SE2(np.pi / 2, 5.0, -1.0), Sensed(None, None, odom, None, scan))  # the same rigid map
    expected = np.array([agent.believed_pose(odom[:2] + p) for p in scan])
    np.testing.assert_allclose(views.returns, expected, atol=1e-12)
    rc = sg.to_cells(views.grid, expected)
    assert (views.grid.cells[rc[:, 0], rc[:, 1]] == sg.OCCUPIED).all()
    np.testing.assert_allclose(views.robot, agent.believed_pose(odom))


def test_a_believed_transition_crossed_by_a_return_makes_its_source_preferred():
    from cogmap.agent.config import AgentConfig
    from cogmap.agent.viewmap import ViewMap

    views = ViewMap(AgentConfig())
    poses = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [1.0, 1.0]])
    # believed-possible transitions both ways along 0-1-2 and 1-3
    src = np.array([0, 1, 1, 2, 1, 3])
    dst = np.array([1, 0, 2, 1, 3, 1])
    views.robot = np.array([0.0, 0.0])
    views.returns = np.zeros((0, 2))
    assert views.doubtful(poses, src, dst, 0).size == 0
    views.returns = np.array([[1.5, 0.02]])  # something now stands between states 1 and 2
    # state 1 can still go elsewhere (to 0 and 3): it is preferred; state 2's only way is blocked
    assert views.doubtful(poses, src, dst, 0).tolist() == [1]
    views.returns = np.zeros((0, 2))  # out of sight now: still preferred until the robot stands on it
    assert views.doubtful(poses, src, dst, 0).tolist() == [1]
    assert views.doubtful(poses, src, dst, 1).size == 0
    # a state behind the obstacle (the robot would see it through the obstacle) is not preferred
    views.doubt.clear()
    poses4 = np.vstack([poses, [[1.0, 2.0]]])
    src4, dst4 = np.append(src, [3, 4]), np.append(dst, [4, 3])  # 3 also reaches a new state 4
    views.robot = np.array([1.0, -1.0])
    views.returns = np.array([[1.0, 0.5]])  # on 1-3, between the robot and state 3
    assert views.doubtful(poses4, src4, dst4, 0).tolist() == [1]  # not 3, hidden behind it
    views.doubt.clear()
    views.robot = np.array([20.0, 0.0])  # too far from the robot to be checked (drift)
    assert views.doubtful(poses, src, dst, 0).size == 0


def test_set_aside_viewpoints_come_back_only_when_the_map_reaches_nearer():
    from cogmap.agent.planner import _revive

    spent = [(np.array([0.0, 0.0]), 3.0), (np.array([10.0, 0.0]), 1.0)]
    # a new state 2 m from the first viewpoint (1 m nearer than before): it comes back
    kept = _revive(spent, np.array([[2.0, 0.0]]), margin=0.5)
    assert [tuple(p) for p, _ in kept] == [(10.0, 0.0)]
    # the map grows far from both (or only 0.4 m nearer): both stay set aside
    assert len(_revive(spent, np.array([[5.0, 5.0], [0.0, 2.6]]), margin=0.5)) == 2
    assert len(_revive(spent, np.zeros((0, 2)), margin=0.5)) == 2
    assert _revive(spent, None, margin=0.5) == []  # states were removed: everything is tried again


def test_parking_lot_exploration_ends_instead_of_shuttling_between_set_aside_viewpoints():
    """Seed 3 in the parking lot: once 98.5 % was seen, reviving every set-aside viewpoint whenever
    the map grew anywhere made the agent shuttle 17 m between two of them for 170 decisions
    (210 decisions, 440 m); a viewpoint now comes back only when a new state lies nearer to it
    (52 decisions, 106 m)."""
    from cogmap.study.runs import explore_episode

    sim, ep, agent, _ = explore_episode("parking_lot", "aimapp", 3, 300)
    try:
        assert len(ep.rows) < 100
        assert ep.coverage[-1] >= 0.95
    finally:
        sim.close()

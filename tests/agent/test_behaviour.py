"""Seeded behaviour of the AIMAPP agent in the numpy box world (no simulator).

Observations name the cell of the true position, so places are recognisable as in a textured
scene; the tests exercise the agent's logic: confidence and kidnapping, drift correction,
sensor dropouts, blocked moves and a moved obstacle.
"""

import numpy as np
import pytest

from cogmap.agent.aimapp import AIMAPPAgent
from cogmap.agent.config import AgentConfig
from cogmap.agent.testing import BoxWorld, CellEncoder, run

CENTRE_BOX = [(2.5, 2.5, 3.5, 3.5)]


def explored(seed, steps=80, **world):
    w = BoxWorld(6, 6, boxes=world.pop("boxes", CENTRE_BOX), start=(1, 1), **world)
    agent = AIMAPPAgent(AgentConfig(), encoder=CellEncoder(), seed=seed)
    decisions, moved = run(w, agent, steps)
    return w, agent, decisions, moved


def belief_error(agent, w):
    return float(np.hypot(*(agent.believed_pose(np.r_[w.odom, 0.0]) - w.true)))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_lost_test_quiet_in_normal_operation_fires_when_kidnapped_and_recovers(seed):
    w, agent, decisions, moved = explored(seed)
    assert agent.counts.lost_events == 0  # does not fire in normal operation
    assert all(d.mode == "explore" for d in decisions)
    assert agent.num_states > 15
    visited = agent.poses[agent.model.live_pA(0).max(axis=0) > 2 * agent.cfg.prior_count]
    far = visited[np.argmax(np.hypot(*(visited - w.true).T))]
    assert np.hypot(*(far - w.true)) > 3.0
    w.kidnap(far)  # moved without odometry
    after, _ = run(w, agent, 20, moved)
    first_lost = next(i for i, d in enumerate(after) if d.mode == "relocalise")
    assert first_lost <= 3
    assert agent.counts.relocalisations >= 1  # found again by what it sees
    assert after[-1].mode == "explore"
    assert belief_error(agent, w) < 0.6


def test_relocalisation_corrects_an_odometry_jump():
    w, agent, _, moved = explored(0, steps=40)
    assert belief_error(agent, w) < 0.05
    w.odometry_jump((0.6, 0.0))  # wheel slip: odometry is now 0.6 m off
    offset = agent.frame.t.copy()
    assert belief_error(agent, w) > 0.55
    errors = []
    run(w, agent, 15, moved, on_step=lambda d: errors.append(belief_error(agent, w)))
    assert np.hypot(*(agent.frame.t - offset)) > 0.5  # the correction moved the belief frame
    assert min(errors) < 0.1  # a recognised place put the belief back on the map
    assert errors[-1] < 0.1


def test_sensor_dropout_pauses_and_resumes_without_reinitialising():
    w, agent, _, moved = explored(0, steps=20)
    model, n_states, q = agent.model, agent.num_states, agent.q.copy()
    w.dropped = set(range(w.steps, w.steps + 5))
    paused, moved = run(w, agent, 5, moved)
    assert [d.mode for d in paused] == ["paused"] * 5
    assert all(d.action == agent.cfg.stay for d in paused)
    assert agent.model is model and agent.num_states == n_states
    np.testing.assert_array_equal(agent.q, q)
    resumed, _ = run(w, agent, 10, moved)
    assert all(d.mode == "explore" for d in resumed)
    assert agent.counts.lost_events == 0
    assert belief_error(agent, w) < 0.05


def test_blocked_move_lowers_the_transition_and_replans():
    # a box the obstacle signal cannot see (a LiDAR blind spot, like a flat chair) right of the start
    w = BoxWorld(6, 6, boxes=[], hidden=[(1.6, 2.6, 2.4, 3.4)], start=(1, 3))
    agent = AIMAPPAgent(AgentConfig(), encoder=CellEncoder(), seed=0)
    failures = []
    moved = None
    for _ in range(30):
        d = agent.step(w.sense(moved))
        before = None if d.target == d.state else agent.model.B[0].column(d.state, d.action, agent.num_states)[d.target]
        moved = w.act(d, agent.cfg.stay)
        if not moved:
            failures.append((d.state, d.action, d.target, before))
    assert failures, "the hidden wall should have blocked at least one move"
    s, a, t, before = failures[0]
    after = agent.model.B[0].column(s, a, agent.num_states)[t]
    assert before > 0.5 and after < 0.05  # experienced impossible: -7 counts (Table 7)
    assert len(failures) <= 6  # it replans instead of insisting
    assert not any(1.6 - 0.22 < p[0] < 2.4 + 0.22 and 2.6 - 0.22 < p[1] < 3.4 + 0.22 for p in w.path)


def test_moved_obstacle_suppresses_transitions_into_the_blocked_node():
    """Section 4.3 / Figure 8: a box moved onto a visited node."""
    w, agent, _, moved = explored(1, steps=60, boxes=[])
    poses = agent.poses
    visited = np.flatnonzero(agent.model.live_pA(0).max(axis=0) > 2 * agent.cfg.prior_count)
    inner = [s for s in visited if 1.5 < poses[s, 0] < 4.5 and 1.5 < poses[s, 1] < 4.5
             and np.hypot(*(poses[s] - w.true)) > 1.5]
    node = inner[0]
    x, y = poses[node]
    w.boxes.append((x - 0.3, y - 0.3, x + 0.3, y + 0.3))  # the box now covers the node
    B = agent.model.B[0]

    def p_move(s, n):
        """Largest believed probability of reaching n from s in one move."""
        return max((B.prob[s, a, k] for a in range(12) for k in range(B.slots) if B.succ[s, a, k] == n), default=0.0)

    neighbours = [s for s in range(agent.num_states) if s != node and np.hypot(*(poses[s] - poses[node])) < 1.2]
    assert max(p_move(s, node) for s in neighbours) > 0.9  # the node was believed reachable
    states = []
    run(w, agent, 25, moved, on_step=lambda d: states.append(d.state))
    revisited = [s for s in neighbours if states.count(s) >= 2]
    assert len(revisited) >= 2
    for s in revisited:
        free = [n for n in range(agent.num_states)
                if n not in (node, s) and 0.5 < np.hypot(*(poses[n] - poses[s])) < 1.2]
        assert p_move(s, node) < 0.1 < max(p_move(s, n) for n in free)
    # it routes around: the robot never drove into the box
    assert not any(x - 0.52 < p[0] < x + 0.52 and y - 0.52 < p[1] < y + 0.52 for p in w.path[-25:])


def box_world_astar(w: BoxWorld, start, goal, res: float = 0.05) -> float:
    from cogmap.planning.astar import astar_grid

    ny, nx = int(w.size[1] / res), int(w.size[0] / res)
    ys, xs = (np.mgrid[0:ny, 0:nx] + 0.5) * res
    occupied = ~np.vectorize(lambda x, y: w.free((x, y)))(xs, ys)
    cell = lambda p: (int(p[1] / res), int(p[0] / res))  # noqa: E731
    return astar_grid(occupied, cell(start), cell(goal), res)[1]


@pytest.mark.parametrize("seed", [0, 1])
def test_goal_reaching_follows_a_short_path(seed):
    w = BoxWorld(8, 6, boxes=[(2.5, 1.5, 3.5, 4.5), (5, 2, 6, 6)], start=(1, 1))
    agent = AIMAPPAgent(AgentConfig(), encoder=CellEncoder(), seed=seed)
    _, moved = run(w, agent, 100)
    visited = np.flatnonzero(agent.model.live_pA(0).max(axis=0) > 2 * agent.cfg.prior_count)
    far = visited[np.argmax(np.hypot(*(agent.poses[visited] - w.true).T))]
    assert np.hypot(*(agent.poses[far] - w.true)) > 4.0
    agent.set_goal(int(agent.model.live_A(0)[:, far].argmax()))
    start, first = w.true.copy(), len(w.path) - 1
    for _ in range(40):
        d = agent.step(w.sense(moved))
        if agent.at_goal:
            break
        assert d.mode == "goal"
        moved = w.act(d, agent.cfg.stay)
    assert agent.at_goal
    travelled = float(np.hypot(*np.diff(np.array(w.path[first:]), axis=0).T).sum())
    assert travelled <= 2.0 * box_world_astar(w, start, w.true)

"""Seeded AIMAPP runs in pybullet rooms (short budgets; the full runs are the reproduction studies)."""

import csv
import json

import networkx as nx
import numpy as np
import pytest

from cogmap.agent.aimapp import AIMAPPAgent
from cogmap.cli import main
from cogmap.explore import default_config, explore, make_sim, run_agent
from cogmap.genmodel.io import load

pytest.importorskip("pybullet", reason="the sim extra is needed for pybullet runs")

STEPS = 40  # step budget for the mini warehouse


def test_mini_warehouse_coverage_in_four_of_five_seeds():
    results = [explore("mini_warehouse", steps=STEPS, seed=seed, progress=False) for seed in range(5)]
    covered = [r["coverage"] >= 0.90 for r in results]
    assert sum(covered) >= 4, [round(r["coverage"], 3) for r in results]
    for r in results:
        assert r["failed_moves"] <= 3
        assert 10 <= r["num_states"] <= 60
        assert r["rmse_belief_m"] < 0.05  # exact odometry: belief stays on the truth


def test_command_line_main_job_writes_a_complete_run(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["explore", "--steps", "12", "--patience", "0", "--seed", "3", "--out", str(out), "--quiet"]) == 0
    names = {p.name for p in out.iterdir()}
    assert {"run.json", "model.npz", "model.json", "map.graphml", "trajectory.csv", "metrics.json", "map.png",
            "coverage.png", "observations"} <= names
    metrics = json.loads((out / "metrics.json").read_text())
    rows = list(csv.DictReader(open(out / "trajectory.csv")))
    assert len(rows) == metrics["steps"] == 12
    assert {"true_x", "odom_x", "belief_x", "state", "action"} <= set(rows[0])
    model = load(out / "model")
    assert model.num_states[0] == metrics["num_states"]
    graph = nx.read_graphml(out / "map.graphml")
    assert graph.number_of_nodes() == metrics["num_states"]
    assert len(list((out / "observations").glob("*.png"))) == model.num_obs[0]
    manifest = json.loads((out / "run.json").read_text())
    assert manifest["seed"] == 3 and manifest["config"]["influence_radius"] == 1.0 and "commit" in manifest
    assert "coverage" in capsys.readouterr().out


def test_camera_dropout_keeps_moving_and_mapping_on_odometry_and_lidar():
    cfg = default_config("mini_warehouse")
    sim = make_sim("mini_warehouse", cfg, 0)
    try:
        agent = AIMAPPAgent(cfg, seed=0)
        decisions = []
        sim.inject_fault("camera", 6, 6)
        run_agent(sim, agent, 16, progress=False, on_step=decisions.append)
        silent = decisions[6:12]
        assert [d.missing for d in silent] == [("camera",)] * 6
        assert all(not d.missing for d in decisions[:6] + decisions[12:])
        assert "paused" not in [d.mode for d in decisions]
        assert sum(d.action != cfg.stay for d in silent) >= 4  # it keeps exploring without the camera
        assert agent.counts.lost_events == 0
        assert np.hypot(*(agent.believed_pose(sim.odometry()) - sim.true_pose()[:2])) < 0.05
    finally:
        sim.close()


def test_lidar_dropout_localises_by_camera_and_moves_only_along_known_transitions():
    cfg = default_config("mini_warehouse")
    sim = make_sim("mini_warehouse", cfg, 1)
    try:
        agent = AIMAPPAgent(cfg, seed=1)
        run_agent(sim, agent, 12, progress=False)
        known = agent.num_states
        decisions = []
        sim.inject_fault("lidar", sim.step_count, 8)
        run_agent(sim, agent, 8, progress=False, on_step=decisions.append)
        assert [d.missing for d in decisions] == [("lidar",)] * 8
        assert all(d.expanded == 0 for d in decisions) and agent.num_states == known  # no expansion blind
        moves = [d for d in decisions if d.action != cfg.stay]
        assert moves and all(d.target != d.state for d in moves)  # only toward states it knows
        assert all(d.mode == "explore" for d in decisions)
        assert np.hypot(*(agent.believed_pose(sim.odometry()) - sim.true_pose()[:2])) < 0.05
        after = []
        run_agent(sim, agent, 10, progress=False, on_step=after.append)
        assert not any(d.missing for d in after) and agent.num_states > known  # expands again
    finally:
        sim.close()


def test_thirty_step_lidar_dropout_does_not_end_exploration():
    from cogmap.explore import Done

    cfg = default_config("house")
    sim = make_sim("house", cfg, 0)
    try:
        agent = AIMAPPAgent(cfg, seed=0)
        done = Done(agent, 20)
        sim.inject_fault("lidar", 10, 30)
        ep = run_agent(sim, agent, 90, progress=False, stop=done)
        assert len(ep.rows) == 90  # 30 blind decisions do not count toward the patience of 20
        assert sum(r["missing"] == "lidar" for r in ep.rows) == 30
        covered_blind = ep.coverage[39] - ep.coverage[10]
        assert covered_blind == 0.0  # a silent LiDAR adds no coverage
        assert ep.coverage[-1] > ep.coverage[40] + 0.2  # exploration goes on after the dropout
    finally:
        sim.close()


def _explored(env, seed, steps, noise=None):
    cfg = default_config(env)
    sim = make_sim(env, cfg, seed, noise)
    agent = AIMAPPAgent(cfg, seed=seed)
    episode = run_agent(sim, agent, steps, progress=False)
    return sim, agent, episode


def _farthest_visited(agent, xy):
    visited = np.flatnonzero(agent.visited())
    return int(visited[np.argmax(np.hypot(*(agent.poses[visited] - xy).T))])


def _goal_run(env, seed, explore_steps, noise=None):
    from cogmap.goal import pursue

    sim, agent, ep = _explored(env, seed, explore_steps, noise)
    try:
        goal_state = _farthest_visited(agent, agent.believed_pose(sim.odometry()))
        goal_obs = int(agent.model.live_A(0)[:, goal_state].argmax())
        _, summary = pursue(sim, agent, goal_obs, 80, progress=False)
        return ep.coverage[-1], agent.counts.lost_events, summary
    finally:
        sim.close()


@pytest.mark.heavy
def test_goal_reaching_in_the_house_four_of_five_seeds_within_twice_astar():
    runs = [_goal_run("house", seed, 150) for seed in range(5)]
    reached = [s for _, _, s in runs if s["reached"]]
    assert len(reached) >= 4, runs
    assert all(s["path_ratio"] <= 2.0 for s in reached), [s["path_ratio"] for s in reached]
    assert all(s["astar_m"] > 8.0 for s in reached)  # goals across the house, not next door
    assert all(lost == 0 for _, lost, _ in runs)  # the lost test stays quiet in normal operation


@pytest.mark.heavy
def test_goal_reaching_with_five_percent_odometry_drift():
    from cogmap.envs import OdometryNoise

    runs = [_goal_run("small_warehouse", seed, 100, OdometryNoise(slip=0.05)) for seed in range(3)]
    assert all(s["reached"] for _, _, s in runs), runs


def test_kidnapped_robot_is_noticed_and_found_again():
    for seed in range(2):
        sim, agent, _ = _explored("mini_warehouse", seed, 60)
        try:
            assert agent.counts.lost_events == 0
            far = _farthest_visited(agent, sim.true_pose()[:2])
            assert np.hypot(*(agent.poses[far] - sim.true_pose()[:2])) > 3.0
            sim.teleport((*agent.poses[far], sim.true_pose()[2]))  # odometry does not notice
            modes: list[str] = []
            run_agent(sim, agent, 20, progress=False, on_step=lambda d, out=modes: out.append(d.mode))
            assert "relocalise" in modes[:3] and agent.counts.lost_events == 1
            assert agent.counts.relocalisations == 1 and modes[-1] == "explore"
            assert np.hypot(*(agent.believed_pose(sim.odometry()) - sim.true_pose()[:2])) < 1.2
        finally:
            sim.close()


def test_box_moved_onto_a_node_lowers_transitions_into_it():
    sim, agent, _ = _explored("mini_warehouse", 2, 60)
    try:
        P = agent.poses
        here = sim.true_pose()[:2]
        visited = np.flatnonzero(agent.visited())
        node = next(int(s) for s in visited if 1.6 < P[s, 0] < 5.0 and 1.3 < P[s, 1] < 4.7
                    and np.hypot(*(P[s] - here)) > 1.5 and np.hypot(*(P[s] - [3.3, 3.0])) > 1.2)
        sim.move_obstacle("central_box", tuple(P[node]))
        B = agent.model.B[0]

        def p_move(s, n):
            return max((B.prob[s, a, k] for a in range(12) for k in range(B.slots) if B.succ[s, a, k] == n),
                       default=0.0)

        neighbours = [s for s in range(agent.num_states) if s != node and np.hypot(*(P[s] - P[node])) < 1.2]
        assert min(p_move(s, node) for s in neighbours) > 0.9
        states = []
        ep = run_agent(sim, agent, 25, progress=False, on_step=lambda d: states.append(d.state))
        came_back = [s for s in neighbours if s in states]
        assert came_back
        assert all(p_move(s, node) <= 0.5 for s in came_back)
        assert all(r["state"] != node for r in ep.rows)  # never believed itself inside the box
        assert sum(r["moved"] is False for r in ep.rows) <= 1
    finally:
        sim.close()


def test_exploration_ends_by_itself_once_nothing_is_left_to_visit():
    result = explore("mini_warehouse", steps=300, seed=0, progress=False, patience=20)
    assert result["ended_by_agent"] and result["steps"] < 150
    assert result["coverage"] >= 0.95
    never = explore("mini_warehouse", steps=60, seed=0, progress=False, patience=0)
    assert not never["ended_by_agent"] and never["steps"] == 60


def test_aliased_racks_do_not_make_the_agent_lost_with_exact_odometry():
    # Large warehouse, seed 0: at decision 53 a view that also belongs to another rack used to fire
    # the lost test and re-localise the agent 3-4 m away; the LiDAR scan, which still aligns with
    # the place the belief is at, now marks the conflict as aliasing.
    sim, agent, episode = _explored("large_warehouse", 0, 70)
    try:
        assert agent.counts.lost_events == 0
        errors = [np.hypot(r["belief_x"] - r["true_x"], r["belief_y"] - r["true_y"]) for r in episode.rows]
        assert max(errors) < 0.2
    finally:
        sim.close()


def test_house_exploration_ends_once_its_own_sensed_map_has_nothing_left_to_see():
    result = explore("house", steps=300, seed=1, progress=False, patience=20)
    assert result["ended_by_agent"] and result["steps"] < 150  # it used to walk all 300 decisions
    assert result["coverage"] >= 0.95


@pytest.mark.parametrize("seed", [0, 3])
def test_goals_are_reached_after_a_short_exploration_of_the_mini_warehouse(seed):
    # The mini warehouse is sensed within 6-10 decisions, so the goals lie 4-5 believed steps away
    # from the start. Offered away from a goal state, "stay" won MCTS's visits there (its subtree
    # holds every move a step later) and the robot waited in place for all 60 decisions.
    from cogmap.study.runs import explore_episode, goal_runs

    sim, _, explored, _ = explore_episode("mini_warehouse", "aimapp", seed, 60)
    sim.close()
    params = {"goals_per_run": 2, "goal_steps": 60, "min_goal_distance": 1.5}  # the goals study's
    results = goal_runs({"env": "mini_warehouse", "seed": seed}, explored, params)
    assert len(results) == 2
    assert all(r["reached"] and r["steps"] <= 15 for r in results), results


def test_explore_episode_hook_sees_every_planning_call_and_leaves_the_run_unchanged():
    from cogmap.study.runs import explore_episode

    calls = []
    sim, plain, _, _ = explore_episode("mini_warehouse", "aimapp", 1, 30)
    sim.close()
    sim, watched, agent, _ = explore_episode("mini_warehouse", "aimapp", 1, 30,
                                             on_step=lambda s, a: calls.append((s.true_pose()[:2].copy(), a)))
    sim.close()
    assert [r["true_x"] for r in watched.rows] == [r["true_x"] for r in plain.rows]
    assert [r["true_y"] for r in watched.rows] == [r["true_y"] for r in plain.rows]
    # called before each move: the pose it sees is the pose the decision's row records
    assert len(calls) >= len(watched.rows) - 1 and all(a is agent for _, a in calls)
    for (xy, _), row in zip(calls, watched.rows, strict=False):
        assert np.allclose(xy, [row["true_x"], row["true_y"]])
    with pytest.raises(ValueError, match="on_step is for AIMAPP"):
        explore_episode("mini_warehouse", "random", 1, 5, on_step=lambda s, a: None)


def test_told_the_outline_aimapp_no_longer_walks_down_the_small_warehouse_aisle():
    # Seed 0 starts at the west mouth of the central aisle. Without the outline the far end of the
    # aisle promises 46 m2, 30 of them outside the building, and the robot walks 7 m down it
    # (13 m to 90 % coverage); told the outline it reaches 90 % within 8 m (docs/exploration.md).
    from cogmap.envs.layouts import LAYOUTS
    from cogmap.study.runs import explore_episode

    def to_90(config):
        sim, ep, agent, _ = explore_episode("small_warehouse", "aimapp", 0, 20, config=config)
        sim.close()
        hit = np.flatnonzero(np.asarray(ep.coverage) >= 0.9)
        return float(ep.distance[hit[0]]), agent

    bounds = LAYOUTS["small_warehouse"]().bounds
    plain, _ = to_90(None)
    told, agent = to_90({"view_bounds": bounds})
    assert agent.cfg.view_bounds == tuple(bounds)
    assert told <= 8.5 and plain >= 12.0, (told, plain)
    with pytest.raises(TypeError):
        explore_episode("small_warehouse", "aimapp", 0, 1, config={"no_such_field": 1})

"""Navigation with hybrid A* in the pybullet mazes: the true simulator as the planner's world, a
small learned model, the pose grid, the run directory and the study's specs."""

import json

import numpy as np
import pytest

from cogmap.cli import build_parser
from cogmap.dvbf.navigate import learn_model, navigate_pairs, navigate_run
from cogmap.envs.maze import make_maze
from cogmap.envs.maze_poses import execute, grid_poses, pose_pairs, summarise
from cogmap.envs.maze_sim import MazeSim
from cogmap.genmodel.dvbf_scan import learned_scan_fn
from cogmap.planning.hybrid_astar import HybridAStarConfig, plan_path


def test_grid_poses_are_free_and_distinct():
    maze = make_maze(1)
    poses = grid_poses(maze)
    assert poses.shape == (25, 3)
    with MazeSim(maze) as sim:
        assert sim.lidar_batch(poses).min() > 0.05  # cell centres, away from every wall
    assert len(pose_pairs(25)) == 600
    sub = pose_pairs(25, 40, seed=3)
    assert len(sub) == 40 == len(set(sub)) and sub == pose_pairs(25, 40, seed=3)
    assert all(i != j for i, j in sub)


def test_plan_in_the_true_simulator_reaches_its_goal():
    maze = make_maze(1)
    poses = grid_poses(maze)
    start, goal = poses[0], poses[12]  # a corner and the centre
    with MazeSim(maze) as sim:
        plan = plan_path(start, goal, sim.lidar_batch, maze.size)
        assert plan.found, plan.reason
        executed, blocked = execute(sim, start, plan.controls)
    assert blocked == 0
    assert np.hypot(*(executed[-1, :2] - goal[:2])) <= 0.05
    assert np.allclose(executed, plan.poses, atol=1e-6)  # open loop, noise free: the plan is what happens
    assert plan.length > np.hypot(*(goal[:2] - start[:2]))  # the walls force a longer path


COARSE = HybridAStarConfig(step=0.04, cell=0.025)  # fewer cells and expansions: quicker tests


@pytest.fixture(scope="module")
def small_model():
    maze = make_maze(4, "simple", "medium")  # 0.5 x 0.5, 12 x 12 map
    return maze, learn_model(maze, steps=400, iters=150, seed=0, hidden=32, map_side=maze.map_side)


def test_learned_model_predicts_the_walls(small_model):
    maze, (params, cfg, _) = small_model
    poses = grid_poses(maze, 3)
    with MazeSim(maze) as sim:
        truth = sim.lidar_batch(poses)
    pred = learned_scan_fn(params, cfg, k_std=0.0)(poses)
    assert pred.shape == truth.shape
    assert np.median(np.abs(pred - truth)) < 0.03
    # the planning ranges lie below the mean by the prediction's spread under q(M)
    low = learned_scan_fn(params, cfg)(poses)
    assert np.all(low < pred) and np.median(pred - low) > 1e-4


def test_learned_plan_is_collision_free_on_an_easy_pair(small_model):
    maze, (params, cfg, _) = small_model
    poses = grid_poses(maze, 3)
    # neighbouring cells with no wall between them: the easy pairs
    easy = [(a, b) for a in range(9) for b in range(9)
            if maze.cell_of(poses[b][:2]) in maze.neighbours(*maze.cell_of(poses[a][:2]))][:2]
    with MazeSim(maze) as sim:
        rows, _ = navigate_pairs(maze, {"learned": learned_scan_fn(params, cfg), "true": sim.lidar_batch}, poses,
                                 easy, COARSE)
    for r in rows:
        assert r["found"] and r["blocked_moves"] == 0 and r["success"], r
    s = summarise(rows)
    assert s["learned"]["success_rate"] == 1.0 and s["length_ratio"]["pairs"] == len(easy)


def test_navigate_run_directory(tmp_path, small_model):
    maze, model = small_model
    out = tmp_path / "nav"
    metrics = navigate_run(maze.seed, out, pairs=1, complexity="simple", corridor="medium", model=model,
                           progress=False, grid=3, config=COARSE)
    for name in ("run.json", "model.npz", "model.json", "poses.csv", "pairs.csv", "metrics.json", "paths.png"):
        assert (out / name).is_file(), name
    assert json.loads((out / "metrics.json").read_text()) == json.loads(json.dumps(metrics))
    assert metrics["pairs"] == 1 and metrics["true"]["pairs"] == metrics["learned"]["pairs"] == 1
    from cogmap.inference.dvbf_files import load_params

    params, cfg = load_params(out)  # the model the plans used, as --model would read it back
    assert cfg == model[1] and np.allclose(np.asarray(params.q_map.mean), np.asarray(model[0].q_map.mean))
    rows = (out / "pairs.csv").read_text().splitlines()
    assert len(rows) == 1 + 3 and rows[0].startswith("start,goal,model,found,success")  # learned, learned_mean, true


@pytest.mark.heavy
def test_navigate_run_plans_to_the_poses_of_goal_scans(tmp_path, small_model):
    maze, model = small_model
    metrics = navigate_run(maze.seed, tmp_path / "obs", pairs=2, complexity="simple", corridor="medium", model=model,
                           progress=False, grid=3, config=COARSE, observation_goals=True)
    assert metrics["observation"]["pairs"] == 2 and len(metrics["goal_errors"]) == 9
    # the search finds most goal poses in this small model (measured: 8 of 9 within 0.05)
    assert sum(e <= 0.05 for e in metrics["goal_errors"]) >= 6
    rows = (tmp_path / "obs" / "pairs.csv").read_text().splitlines()
    assert len(rows) == 1 + 2 * 4 and "goal_estimate_error" in rows[0]


def test_cli_parses_dvbf_navigate():
    args = build_parser().parse_args(["dvbf", "navigate", "--maze", "3", "--pairs", "10", "--out", "x"])
    assert (args.maze, args.pairs, args.out, args.dvbf_command, args.model) == (3, 10, "x", "navigate", None)
    assert not args.observation_goals
    assert build_parser().parse_args(["dvbf", "navigate", "--observation-goals"]).observation_goals


def test_study_specs_are_blocks_of_pairs():
    from cogmap.study.registry import run_specs, study_plan

    full = run_specs(study_plan("dvbf-navigation", "full"))
    assert len(full) == 2 * 6 * 6  # pose-to-pose and pose-to-observation; six mazes, 600 pairs each in blocks of 100
    for method in ("hybrid_astar", "pose_to_observation"):
        assert sum(s["params"]["last"] - s["params"]["first"] for s in full if s["method"] == method) == 3600
    assert len({s["key"] for s in full}) == len(full)
    with pytest.raises(ValueError, match="methods"):
        study_plan("dvbf-navigation", "full", methods=["dijkstra"])
    from cogmap.inference.goal_encoding import ENCODER
    from cogmap.study.dvbf_navigation import ENCODER as STUDY_ENCODER

    assert STUDY_ENCODER["full"] == ENCODER  # the study searches goal poses as cogmap dvbf navigate does
    reduced = run_specs(study_plan("dvbf-navigation", "reduced"))
    assert [s["env"] for s in reduced] == ["maze1", "maze2"] * 2
    with pytest.raises(ValueError, match="maze<seed>"):
        study_plan("dvbf-navigation", "reduced", envs=["house"])
    assert json.loads(json.dumps(full[0])) == full[0]


@pytest.mark.heavy
def test_pose_to_observation_study_runs_and_reports(tmp_path):
    from cogmap.study.runner import load_runs, run_study

    run = run_study("dvbf-navigation", tmp_path, scale="tiny", progress=False)  # both methods
    assert run["complete"] and run["runs"] == 2
    recs = {r["spec"]["method"]: r for r in load_runs(tmp_path / "dvbf-navigation").values()}
    res = recs["pose_to_observation"]["result"]
    rows = res["rows"]
    assert len(rows) == 2 and {r["model"] for r in rows} == {"observation"}
    # the plans went to the inferred goals and are judged at the true ones
    enc = res["encoded_goals"]
    assert len(enc["poses"]) == len(enc["errors"]) == 25
    for r in rows:
        assert r["goal_estimate_error"] == enc["errors"][r["goal"]]
        assert r["success"] == (r["found"] and r["final_error"] <= 0.05)
    table = (tmp_path / "dvbf-navigation" / "table.md").read_text()
    assert "pose-to-observation" in table and "goal poses found within 0.05" in table
    import csv

    with open(tmp_path / "dvbf-navigation" / "pairs.csv") as f:
        got = list(csv.DictReader(f))
    assert len(got) == 2 * 3 + 2 and {r["model"] for r in got} == {"learned", "learned_mean", "true", "observation"}
    for r in got:  # one column per field whichever method wrote the row
        assert (r["goal_estimate_error"] != "") == (r["model"] == "observation") and r["success"] in ("True", "False")

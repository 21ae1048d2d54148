"""``cogmap dvbf explore`` and ``cogmap reproduce dvbf-exploration`` (baselines only: no model to compile)."""

import csv
import json

import numpy as np
import pytest

from cogmap.cli import build_parser
from cogmap.dvbf.explore import ExploreConfig, explore
from cogmap.dvbf.run import explore_run
from cogmap.envs.maze import exploration_ratio, make_maze
from cogmap.envs.maze_episode import ratio_at
from cogmap.envs.maze_poses import start_pose
from cogmap.planning.maze_explorers import Frontier
from cogmap.study import run_study
from cogmap.study.registry import run_specs, study_plan
from cogmap.study.runner import load_runs


def test_explore_baselines_share_the_start_and_measure_the_ratio():
    maze = make_maze(1, "simple", "small")
    runs = {m: explore(maze, 150, ExploreConfig(method=m, seed=3)) for m in ("random", "frontier")}
    for r in runs.values():
        assert np.allclose(r.poses[0], start_pose(maze, 3))
        assert len(r.poses) == 150 and len(r.controls) == 149
        assert r.ratio_curve[-1] == (149, pytest.approx(exploration_ratio(maze, r.poses)))
        assert np.all(r.controls[:, 1] >= 0) and np.all(r.controls[:, 1] <= 0.01 + 1e-12)
        # the maze walls are respected: the point stays inside
        assert np.all((r.poses[:, :2] > 0) & (r.poses[:, :2] < maze.size))
    assert ratio_at([(0, 0.1), (10, 0.3), (20, 0.5)], 15) == 0.3


def test_frontier_grid_marks_free_and_occupied_cells():
    maze = make_maze(1, "simple", "small")
    f = Frontier(maze, ExploreConfig(method="frontier"), 0, 0.53)
    pose = np.array([maze.cell / 2, maze.cell / 2, 0.0])
    scan = np.full(20, 0.53)
    scan[0] = maze.cell / 2  # a wall half a cell ahead along x
    f.update(pose, scan)
    i, j = f._cell(pose[:2])
    assert f.grid[i, j] == 1 and f.grid[f._cell(pose[:2] + [maze.cell / 2, 0])[0], j] == 2
    assert (f.grid == 0).any()  # the corner beyond the beams is still unknown
    path = f._plan(pose)
    assert path and f.grid[tuple(f._cell(path[-1]))] == 1


def test_explore_run_directory(tmp_path):
    out = tmp_path / "run"
    metrics = explore_run(2, out, steps=80, methods=("random", "frontier"), progress=False)
    for name in ("run.json", "trajectory.csv", "metrics.json", "path.png", "ratio.png"):
        assert (out / name).is_file(), name
    assert json.loads((out / "metrics.json").read_text())["ratio_at_budget"] == metrics["ratio_at_budget"]
    rows = list(csv.DictReader(open(out / "trajectory.csv")))
    assert len(rows) == 2 * 80 and {r["method"] for r in rows} == {"random", "frontier"}
    maze = make_maze(2, "simple", "small")
    xy = np.array([[float(r["true_x"]), float(r["true_y"])] for r in rows if r["method"] == "random"])
    assert metrics["ratio_at_budget"]["random"] == pytest.approx(exploration_ratio(maze, xy))
    with pytest.raises(ValueError, match="maze 0"):
        explore_run(0, tmp_path / "x", steps=10, methods=("random",), progress=False)


def test_cli_parses_dvbf_explore():
    args = build_parser().parse_args(["dvbf", "explore", "--maze", "3", "--steps", "50", "--out", "x",
                                      "--methods", "mi", "random"])
    assert (args.maze, args.steps, args.out, args.dvbf_command, args.methods) == (3, 50, "x", "explore",
                                                                                  ["mi", "random"])
    assert build_parser().parse_args(["dvbf", "explore"]).steps is None  # the Table II budget


def test_study_plan_and_keys():
    from cogmap.dvbf.explore import RUN_METHODS
    from cogmap.study.dvbf_exploration import METHODS

    assert METHODS == RUN_METHODS  # the study names every method a run can
    plan = study_plan("dvbf-exploration", "reduced")
    assert plan["envs"] == ["simple-small", "moderate-small", "complex-small"]
    assert plan["steps"] == {"simple-small": 200, "moderate-small": 200, "complex-small": 200}
    assert study_plan("dvbf-exploration", "full")["steps"]["complex-large"] == 18000  # Table II
    assert len(plan["seeds"]) == 5
    specs = run_specs(plan)
    assert len({s["key"] for s in specs}) == len(specs) == 3 * 4 * 5
    pull = [s for s in specs if s["method"] == "mi-pull"]
    assert pull and all(s["method_options"]["pull_below"] > 0 for s in pull)
    with pytest.raises(ValueError, match="Table II rows"):
        study_plan("dvbf-exploration", "reduced", envs=["moderate"])
    with pytest.raises(ValueError, match="method"):
        study_plan("dvbf-exploration", "reduced", methods=["pema"])


def test_study_runs_and_resumes(tmp_path):
    kw = dict(scale="tiny", methods=["random", "frontier"], seeds=[0, 1], progress=False)
    first = run_study("dvbf-exploration", tmp_path, **kw)
    assert first["complete"] and first["runs"] == 4
    stored = load_runs(tmp_path / "dvbf-exploration")
    again = run_study("dvbf-exploration", tmp_path, **kw)
    assert again["runs"] == 4 and load_runs(tmp_path / "dvbf-exploration") == stored  # nothing redone
    table = (tmp_path / "dvbf-exploration" / "table.md").read_text()
    assert "PEMA" in table and "frontier" in table
    for f in ("table.csv", "runs.csv", "ratio.png", "study.json"):
        assert (tmp_path / "dvbf-exploration" / f).is_file()


def test_frontier_goes_around_a_wall_it_bumped_into():
    # complex / small maze 1, seed 0: before the frontier explorer marked the cell ahead of a bump as
    # occupied it re-planned the same path into the same wall and was blocked on 5,538 of 6,000 steps
    from cogmap.dvbf.explore import ExploreConfig, explore
    from cogmap.envs.maze import make_maze

    res = explore(make_maze(1, "complex", "small"), 2000, ExploreConfig(method="frontier", seed=0))
    assert res.blocked < 400 and res.ratio_curve[-1][1] > 0.4

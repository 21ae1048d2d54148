"""``cogmap dvbf slam``: the run directory and the parameter round trip."""

import csv
import json

import numpy as np
import pytest

from cogmap.cli import build_parser
from cogmap.dvbf.run import load_params, slam_run
from cogmap.dvbf.slam import path_integration


def test_slam_run_directory(tmp_path):
    out = tmp_path / "run"
    # a small maze and few training steps keep compile and run time short
    metrics = slam_run(2, 30, out, progress=False, complexity="simple", corridor="medium", train_iters=2,
                       marginal=False, pretrain_maze=None)
    for name in ("run.json", "model.npz", "model.json", "trajectory.csv", "metrics.json", "error.png", "map.png"):
        assert (out / name).is_file(), name
    assert json.loads((out / "metrics.json").read_text()) == metrics
    assert metrics["steps"] == 30 and metrics["training_steps"] == 3 * 2 and metrics["pretrain_maze"] is None
    assert json.loads((out / "run.json").read_text())["config"]["freeze_emission"] is False
    rows = list(csv.DictReader(open(out / "trajectory.csv")))
    assert len(rows) == 30
    true = np.array([[float(r["true_x"]), float(r["true_y"])] for r in rows])
    est = np.array([[float(r["est_x"]), float(r["est_y"])] for r in rows])
    assert np.allclose(est[0], true[0], atol=1e-6)  # the known start
    assert np.max(np.hypot(*(est - true).T)) < 0.1
    assert float(rows[-1]["error"]) == pytest.approx(metrics["error_final"], abs=1e-6)
    params, cfg = load_params(out)
    data = np.load(out / "model.npz")
    assert np.allclose(np.asarray(params.q_map.mean), data["q_map/mean"])
    assert cfg.map_side == 12 and params.q_map.mean.shape == (12, 12, 20)  # Table II, simple / medium


def test_pretraining_maze_must_differ(tmp_path):
    with pytest.raises(ValueError, match="another maze"):
        slam_run(0, 10, tmp_path, progress=False, pretrain_maze=0)


def test_cli_parses_dvbf_slam():
    args = build_parser().parse_args(["dvbf", "slam", "--maze", "3", "--steps", "50", "--out", "x"])
    assert (args.maze, args.steps, args.out, args.dvbf_command) == (3, 50, "x", "slam")


def test_path_integration_rotates_then_moves():
    poses = path_integration([0.5, 0.5, 0.0], [[np.pi / 2, 0.1], [-np.pi / 2, 0.2]])
    assert np.allclose(poses[-1], [0.7, 0.6, 0.0], atol=1e-9)

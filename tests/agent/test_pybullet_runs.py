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
    assert main(["explore", "--steps", "12", "--seed", "3", "--out", str(out), "--quiet"]) == 0
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


def test_camera_dropout_pauses_then_resumes_in_pybullet():
    cfg = default_config("mini_warehouse")
    sim = make_sim("mini_warehouse", cfg, 0)
    try:
        agent = AIMAPPAgent(cfg, seed=0)
        modes = []
        sim.inject_fault("camera", 6, 4)
        run_agent(sim, agent, 16, progress=False, on_step=lambda d: modes.append(d.mode))
        assert modes[6:10] == ["paused"] * 4
        assert "paused" not in modes[:6] + modes[10:]
        assert agent.lost_events == 0
        assert np.hypot(*(agent.believed_pose(sim.odometry()) - sim.true_pose()[:2])) < 0.05
    finally:
        sim.close()

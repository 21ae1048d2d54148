"""The recovery study: its plan, its grid task, a real (small) fit on the grid, and its report."""

from __future__ import annotations

import json

import jax
import numpy as np
import pytest

from cogmap.envs import jax_worlds
from cogmap.study import recovery
from cogmap.study.registry import run_specs, study_plan


def test_the_plan_crosses_tasks_kinds_and_datasets_and_refuses_unknown_names():
    specs = run_specs(study_plan("recovery", "tiny"))
    assert sorted((s["env"], s["method"]) for s in specs) == [("grid", "model"), ("grid", "parameter"),
                                                              ("tmaze", "model"), ("tmaze", "parameter")]
    assert len(run_specs(study_plan("recovery", "full"))) == 4 * recovery.SCALE["full"]["seeds"]
    with pytest.raises(ValueError, match=r"unknown recovery environment\(s\) \['maze'\]"):
        study_plan("recovery", "tiny", envs=["maze"])
    with pytest.raises(ValueError, match=r"unknown recovery method\(s\) \['nuts'\]"):
        study_plan("recovery", "tiny", methods=["nuts"])


def test_the_landmark_grid_has_exact_landmarks_a_noisy_sensor_elsewhere_and_a_rising_preference():
    m = jax_worlds.landmark_grid_model(side=5, goal_preference=3.0, reliability=0.4)
    A, C, D = m.live_A(0), m.live_C(0), m.live_D(0)
    np.testing.assert_allclose(A.sum(axis=0), 1.0)
    middle = [2 * 5 + x for x in range(5)]
    for s in range(25):
        expected = 1.0 if s in middle else 0.4 + 0.6 / 25
        assert A[s, s] == pytest.approx(expected)
    assert C[0] == 0.0 and C[24] == pytest.approx(3.0) and C[6] == pytest.approx(3.0 * 2 / 8)
    np.testing.assert_allclose(D, np.where(np.arange(25) % 5 == 0, 0.2, 0.0))
    with pytest.raises(ValueError, match=r"reliability must be in \(0, 1\], got 0"):
        jax_worlds.landmark_grid_model(reliability=0.0)


def test_precisions_fitted_on_the_grid_task_follow_the_true_ones():
    with jax.enable_x64(True):
        res = recovery.parameter_recovery("grid", 3, subjects=6, trials=30, iterations=150)
    true, fitted = np.asarray(res["true"]), np.asarray(res["fitted"])
    assert true.shape == fitted.shape == (6,)
    assert res["correlation"] > 0.8, res
    assert res["median_relative_error"] < 0.3, res


def test_the_report_tables_the_runs_against_the_targets_and_draws_both_figures(tmp_path):
    plan = study_plan("recovery", "tiny", envs=["tmaze"])
    good = {"true": [1.0, 2.0, 4.0], "fitted": [1.05, 1.9, 4.2], "median_relative_error": 0.05,
            "correlation": 0.99}
    M = [[0.9, 0.1, 0.0], [0.0, 1.0, 0.0], [0.2, 0.0, 0.8]]
    model = {"candidates": ["efe", "utility only", "information only"], "confusion": M, "recovered": 0.9}
    results = [{"spec": {"env": "tmaze", "method": "parameter", "seed": 0}, "result": good},
               {"spec": {"env": "tmaze", "method": "model", "seed": 0}, "result": model}]
    text = recovery.recovery_report(tmp_path, plan, json.loads(json.dumps(results)))
    assert "| tmaze | 0 | 6 | 8 | 2 | 0.050 | 0.990 | yes |" in text
    assert "| **information only** | 0.20 | 0.00 | 0.80 |" in text
    assert "recovered in 0.900 of the simulated subjects" in text
    assert (tmp_path / "parameters.png").stat().st_size > 0 and (tmp_path / "confusion.png").stat().st_size > 0
    assert (tmp_path / "parameters.csv").read_text().splitlines()[1] == "tmaze,0,1.0,1.05"
    bad = {**good, "correlation": 0.5}
    text = recovery.recovery_report(tmp_path, plan, [{"spec": {"env": "tmaze", "method": "parameter", "seed": 0},
                                                      "result": bad}])
    assert "| 0.050 | 0.500 | no |" in text

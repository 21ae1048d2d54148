"""Study metrics on hand-made trajectories with known answers."""

import math

import numpy as np
import pytest

from cogmap.study.metrics_extra import (
    count_stalls,
    drift_metrics,
    fraction_within,
    graph_plan_length,
    is_success,
    nauc_budget,
    nauc_over_budget,
    path_length_ratios,
    summarise,
    transitions_into,
)


def test_nauc_over_a_fixed_budget_holds_the_last_coverage():
    # coverage 0.5 from 0 to 2 m, then 1.0: over a 4 m budget the area is 0.5*2 + 1*2 = 3
    assert nauc_over_budget([0.0, 2.0], [0.5, 1.0], budget=4.0) == pytest.approx(0.75)
    assert nauc_budget(36.0) == pytest.approx(18.0)


def test_stalls_count_failed_runs_and_flat_coverage():
    moved = [None] + [False] * 5 + [True] * 3
    cov = np.linspace(0.1, 0.5, len(moved)).tolist()
    assert count_stalls(moved, cov, fail_run=5) == 1
    # 4 failures then a success: no stall
    assert count_stalls([None, False, False, False, False, True], [0.1, 0.2, 0.3, 0.4, 0.5, 0.6]) == 0
    # 50 decisions without coverage gain below target: two stalls of 25
    flat = [0.5] * 51
    assert count_stalls([True] * 51, flat, nogain_run=25) == 2
    # flat at full coverage is not a stall
    assert count_stalls([True] * 51, [1.0] * 51, nogain_run=25, target=0.99) == 0
    assert is_success(0.95, 0) and not is_success(0.95, 1) and not is_success(0.8, 0)


def test_drift_metrics_on_a_known_offset():
    # straight 10 m line; odometry 0.3 m to the side all along; belief exact
    t = np.stack([np.linspace(0, 10, 11), np.zeros(11)], 1)
    o = t + np.array([0.0, 0.3])
    d = drift_metrics(t, o, t)
    assert d["rmse_odometry_m"] == pytest.approx(0.3)
    assert d["ate_per_m_odometry"] == pytest.approx(0.03)
    assert d["rmse_belief_m"] == pytest.approx(0.0)
    # NaN rows (dropped odometry) are ignored
    o2 = o.copy()
    o2[3] = np.nan
    assert drift_metrics(t, o2, t)["rmse_odometry_m"] == pytest.approx(0.3)


def test_path_length_ratios_decompose_multiplicatively():
    r = path_length_ratios(12.0, 8.0, 10.0)
    assert r["plr_executed_vs_astar"] == pytest.approx(1.5)
    assert r["plr_executed_vs_plan"] == pytest.approx(1.2)
    assert r["plr_plan_vs_astar"] == pytest.approx(1.25)
    assert r["plr_executed_vs_plan"] * r["plr_plan_vs_astar"] == pytest.approx(r["plr_executed_vs_astar"])
    assert path_length_ratios(5.0, math.inf, 3.0)["plr_executed_vs_astar"] is None
    assert fraction_within([1.1, 1.3, 1.6, None], 1.2) == pytest.approx(1 / 3)


class _Sparse:
    """Padded successor lists: succ/prob of shape (states, actions, slots)."""

    def __init__(self, n, edges):
        self.succ = np.tile(np.arange(n)[:, None, None], (1, 2, 1))
        self.prob = np.ones((n, 2, 1))
        for s, a, t, p in edges:
            self.succ[s, a, 0], self.prob[s, a, 0] = t, p


def test_graph_plan_length_on_a_square_with_a_weak_diagonal():
    # unit square 0-1-2-3 and a diagonal 0->2 believed impossible (p = 0.2)
    poses = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    B = _Sparse(4, [(0, 0, 1, 0.9), (1, 0, 2, 0.9), (0, 1, 2, 0.2), (2, 0, 3, 0.9)])
    assert graph_plan_length(B, poses, 0, [2]) == pytest.approx(2.0)
    B.prob[0, 1, 0] = 0.8  # now the diagonal is believed possible
    assert graph_plan_length(B, poses, 0, [2]) == pytest.approx(math.sqrt(2))
    assert graph_plan_length(B, poses, 0, [3, 2]) == pytest.approx(math.sqrt(2))
    t = transitions_into(B.succ, B.prob, 2, 4)
    assert t["count"] == 2 and t["max"] == pytest.approx(0.9) and t["mean"] == pytest.approx(0.85)
    assert t["above_half"] == 2


def test_summarise_ignores_missing_values():
    s = summarise([1.0, 3.0, None, float("nan")])
    assert s == {"mean": 2.0, "std": 1.0, "median": 2.0, "n": 2}
    assert summarise([])["mean"] is None

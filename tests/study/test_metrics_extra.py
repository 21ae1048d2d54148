"""Study metrics on hand-made trajectories with known answers."""

import math

import numpy as np
import pytest

from cogmap.genmodel import SparseTransitions
from cogmap.study.metrics_extra import (
    SuccessRule,
    drift_metrics,
    duplicates,
    endpoints,
    first_reach,
    fraction_within,
    graph_plan_length,
    interventions,
    nauc_budget,
    nauc_over_budget,
    path_length_ratios,
    summarise,
    trajectory_digest,
    transitions_into,
)


def test_nauc_over_a_fixed_budget_holds_the_last_coverage():
    # coverage 0.5 from 0 to 2 m, then 1.0: over a 4 m budget the area is 0.5*2 + 1*2 = 3
    assert nauc_over_budget([0.0, 2.0], [0.5, 1.0], budget=4.0) == pytest.approx(0.75)
    assert nauc_budget(36.0) == pytest.approx(18.0)


def test_endpoints_at_ninety_percent_and_at_the_end():
    # free area 100 m2, budget 10 m; coverage 0.5 at 0 m, 0.8 at 1 m, 0.92 at 2 m, 0.99 at 4 m
    d, c = [0.0, 1.0, 2.0, 4.0], [0.5, 0.8, 0.92, 0.99]
    e = endpoints(d, c, free_area_m2=100.0, budget=10.0)
    assert e["level_index"] == 2 and first_reach(c, 0.9) == 2
    at = e["at_level"]
    assert at["distance_m"] == 2.0 and at["area_m2"] == pytest.approx(92.0)
    assert at["ce"] == pytest.approx(92.0 / 2.0)
    # cut at 2 m, 0.92 held to the budget: (0.5 * 1 + 0.8 * 1 + 0.92 * 8) / 10
    assert at["nauc"] == pytest.approx((0.5 + 0.8 + 0.92 * 8) / 10)
    end = e["end"]
    assert end["ce"] == pytest.approx(99.0 / 4.0)
    assert end["nauc"] == pytest.approx((0.5 + 0.8 + 0.92 * 2 + 0.99 * 6) / 10)
    # a run that levels off below 90 % has no 90 % endpoint; one that starts above it has no CE there
    flat = endpoints([0.0, 5.0, 9.0], [0.4, 0.85, 0.88], 100.0, 10.0)
    assert flat["at_level"] is None and flat["level_index"] is None
    assert flat["end"]["ce"] == pytest.approx(88.0 / 9.0)
    start = endpoints([0.0, 1.0], [0.95, 0.97], 100.0, 10.0)
    assert start["level_index"] == 0 and start["at_level"]["ce"] is None
    assert start["at_level"]["nauc"] == pytest.approx(0.95)
    # the budget is shorter than the distance to 90 %: only the budget counts
    late = endpoints([0.0, 20.0], [0.5, 0.95], 100.0, 10.0)
    assert late["at_level"]["nauc"] == pytest.approx(0.5) and late["at_level"]["ce"] == pytest.approx(95.0 / 20.0)


RULE = SuccessRule(stuck_decisions=15, stuck_radius_m=0.25, collision_run=5, mismatch_m=1.0, mismatch_decisions=10)


def _walk(n, step=1.0):
    """Back and forth between (0, 0) and (step, 0): moving, but covering nothing new."""
    return np.array([[step * (i % 2), 0.0] for i in range(n)])


def test_levelling_off_is_not_a_failure():
    t = _walk(100)
    assert interventions(t, [None] + [True] * 99, t, RULE) == []
    # isolated failed moves (up to 4 in a row) are recovered by the methods themselves
    moved = [None] + ([False] * 4 + [True]) * 19 + [True] * 4
    assert interventions(t, moved, t, RULE) == []


def test_each_failure_cause_is_found():
    # stuck: standing within 0.2 m for 15 decisions after walking
    t = np.vstack([_walk(6), np.tile([[0.1, 0.1]], (16, 1)) + 0.05 * np.sin(np.arange(16))[:, None]])
    ev = interventions(t, [None] + [True] * (len(t) - 1), t, RULE)
    assert [e["cause"] for e in ev] == ["stuck"] and ev[0]["step"] == 6 + 15
    assert interventions(t[:-1], [None] + [True] * (len(t) - 2), t[:-1], RULE) == []  # 14 decisions: not yet
    # collision: five failed moves in a row (the robot still shuffles a little, so it is not stuck)
    t = _walk(12)
    moved = [None, True, True, False, False, False, False, False, True, True, True, True]
    ev = interventions(t, moved, t, RULE)
    assert ev == [{"cause": "collision", "step": 7}]
    # map mismatch: the belief 1.5 m off for 10 decisions (9 is not enough; NaN is no belief)
    t = _walk(30)
    b = t.copy()
    b[10:20] += [0.0, 1.5]
    assert interventions(t, [None] + [True] * 29, b, RULE) == [{"cause": "map", "step": 19}]
    b[19] = t[19]
    assert interventions(t, [None] + [True] * 29, b, RULE) == []
    b[10:25] = np.nan
    assert interventions(t, [None] + [True] * 29, b, RULE) == []
    # the bound is needed
    with pytest.raises(ValueError):
        interventions(t, [None] * 30, t, SuccessRule())
    assert interventions(t, [None] * 30, t + [0.0, 1.5], SuccessRule(), mismatch_m=2.0) == []


def test_trajectory_digests_find_the_same_run_twice():
    a = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])
    assert trajectory_digest(a) == trajectory_digest(a + 1e-5)  # below a millimetre
    assert trajectory_digest(a) != trajectory_digest(a + [0.0, 0.01])
    assert duplicates({"s0": "x", "s1": "y", "s4": "x"}) == [["s0", "s4"]]
    assert duplicates({"s0": "x", "s1": "y"}) == []


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


def _Sparse(n, edges):  # noqa: N802 - a small factory of padded successor lists
    succ = np.tile(np.arange(n)[:, None, None], (1, 2, 1))
    prob = np.ones((n, 2, 1))
    for s, a, t, p in edges:
        succ[s, a, 0], prob[s, a, 0] = t, p
    return SparseTransitions(succ, prob)


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

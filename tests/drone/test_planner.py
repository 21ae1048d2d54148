"""Waypoint generation, filtering, EFE, shaping and ranking against DRONE.md 2.5-2.6."""

import numpy as np
import pytest

from cogmap.genmodel.suitability import suitability, waypoint_suitability
from cogmap.planning import drone_efe as E
from cogmap.planning.drone_planner import DronePlannerConfig, plan_waypoints
from cogmap.planning.drone_waypoints import (
    candidate_waypoints,
    filter_waypoints,
    policy_length,
    waypoint_count,
    waypoint_radius,
)


@pytest.mark.parametrize(("s", "rho", "d_obs", "d_tgt", "r"), [
    (1.0, 0.0, 10.0, 50.0, 3.5),
    (0.5, 0.0, 10.0, 50.0, 2.25),
    (0.0, 0.0, 10.0, 15.0, 1.0),
    (0.0, 0.2, 2.0, 15.0, 1.35),  # env = mean(0.3, 0.3): floor 1 + 0.5 * 0.7
    (0.0, 0.2, 2.0, 50.0, 2.0),  # at least 2 beyond 20 m
    (0.5, 0.0, 10.0, 8.0, 8.8),  # at least 1.1 d_tgt within 10 m
])
def test_radius(s, rho, d_obs, d_tgt, r):
    assert waypoint_radius(s, rho, d_obs, d_tgt) == pytest.approx(r)


@pytest.mark.parametrize(("s", "rho", "d_obs", "d_tgt", "n"), [
    (0.0, 0.0, 10.0, 50.0, 100),  # 100 * 1.2 clamped
    (1.0, 0.0, 10.0, 50.0, 30),  # 25 * 1.2
    (0.5, 0.0, 10.0, 15.0, 62),  # 62.5 rounds to even
    (1.0, 0.2, 10.0, 15.0, 50),  # dense: x max(2, 1)
    (1.0, 0.0, 2.0, 5.0, 69),  # close: x 2.5, near x 1.1
    (0.5, 0.2, 2.0, 50.0, 100),  # both: x 2.5 x 1.2, far x 1.2, clamped
    (1.0, 0.0, 10.0, 15.0, 25),
])
def test_count(s, rho, d_obs, d_tgt, n):
    assert waypoint_count(s, rho, d_obs, d_tgt) == n


def test_policy_length():
    assert [policy_length(s) for s in (0.0, 0.5, 1.0)] == [5, 4, 2]


def test_candidates_ring_and_target_bias():
    rng = np.random.default_rng(0)
    pos, tgt = np.array([0.0, 0, 10]), np.array([40.0, 0, 10])
    W = candidate_waypoints(pos, tgt, 3.0, 40, rng)
    assert len(W) == 3 * 28 + 12  # 70 % ring x 3 elevations + 30 % target-biased
    ring = W[: 3 * 28]
    np.testing.assert_allclose(np.linalg.norm(ring - pos, axis=1), 3.0)
    biased = W[3 * 28:]
    np.testing.assert_allclose(biased[0], [3.0, 0, 10])  # the direct step min(r, 0.8 d)
    steps = np.linalg.norm(biased - pos, axis=1)
    assert (steps >= 2.25 - 1e-9).all() and (steps <= 3.0 + 1e-9).all()
    cos = (biased - pos) @ np.array([1.0, 0, 0]) / steps
    assert (cos >= np.cos(np.deg2rad(30 * 1.5)) - 1e-9).all()
    low = candidate_waypoints(np.array([0.0, 0, 2]), tgt, 3.0, 40, rng, min_altitude=1.0)
    assert (low[:, 2] >= 1.0).all() and len(low) < len(W)  # the straight-down points are dropped


def test_threshold_relaxes_near_target_and_fallback_cascade():
    pos = np.zeros(3)
    W = np.array([[1.0, 0, 0], [0, 1.0, 0], [-1.0, 0, 0]])
    S = np.array([0.65, 0.7, 0.3])
    far = filter_waypoints(W, S, pos, [50.0, 0, 0], 0.0)
    assert far[1].startswith("fallback 0.4") and list(far[0]) == [1, 0]
    near = filter_waypoints(W, S, pos, [8.0, 0, 0], 0.0)
    assert near[1] == "threshold 0.6" and set(near[0]) == {0, 1}
    none = filter_waypoints(W, np.array([0.1, 0.15, 0.05]), pos, [50.0, 0, 0], 0.0)
    assert none[1] == "fallback argmax" and list(none[0]) == [1]


@pytest.mark.parametrize("d_obs", [1.0, 2.0, 3.0, 3.2])
def test_fallback_fires_whenever_clearance_below_321(d_obs):
    rng = np.random.default_rng(1)
    pos, tgt = np.array([0.0, 0, 5]), np.array([60.0, 0, 5])
    W = candidate_waypoints(pos, tgt, 3.0, 60, rng)
    S = waypoint_suitability(W, np.zeros((0, 3)), d_obs, tgt, pos)
    assert S.max() < 0.75
    assert filter_waypoints(W, S, pos, tgt, 0.0)[1].startswith("fallback")
    S_ok = waypoint_suitability(W, np.zeros((0, 3)), 3.3, tgt, pos)
    assert filter_waypoints(W, S_ok, pos, tgt, 0.0)[1] == "threshold 0.75"


def test_preferences_by_hand():
    assert E.distance_preference(0.0) == pytest.approx(1.0)
    assert E.distance_preference(50.0) == pytest.approx((1 - 0.4) ** 2 * np.exp(-2.5))
    assert E.angle_preference(0.0) == pytest.approx(1.0)
    assert E.angle_preference(np.pi) == pytest.approx(0.2)
    assert E.suitability_preference(0.2, 0.4) == pytest.approx(0.04 / 0.8)
    assert E.suitability_preference(0.7, 0.4) == pytest.approx(0.5 + 0.5 * 0.3 / 0.6)
    # low suitability: w_d = max(2 (1 - f/2), 0.5), w_s = 1 + f with f = 2.5 (0.4 - S)
    f = 2.5 * 0.2
    wd, ws = max(2 * (1 - f / 2), 0.5), 1 + f
    ref = (wd * E.distance_preference(10.0) + 0.5 * 1.0 + ws * E.suitability_preference(0.2)) / (wd + 0.5 + ws)
    assert E.preference(10.0, 0.0, 0.0, 0.2) == pytest.approx(ref)


def test_efe_negative_and_linear_in_step_length():
    pref, bonus = np.array([0.3, 0.8]), np.array([0.0, 0.1])
    for m in (1.0, 2.5):
        G, prag, epi = E.efe(pref, bonus, np.full(2, m), 6.0)
        assert (G <= 0).all()
        np.testing.assert_allclose(prag, -(pref + bonus) * m)
        np.testing.assert_allclose(epi, -0.2 * 0.5 * 6.0 * m)
    G1, _, _ = E.efe(pref, bonus, np.ones(2), 6.0)
    G2, _, _ = E.efe(pref, bonus, np.full(2, 3.0), 6.0)
    np.testing.assert_allclose(G2, 3 * G1)
    G0, _, e0 = E.efe(pref, bonus, np.ones(2), 6.0, w_epistemic=0.0)
    assert (e0 == 0).all()


def test_shaping_and_ranking_switches():
    G = np.array([-2.0, -2.0])
    s = np.array([0.9, 0.5])
    d_new = np.array([60.0, 60.0])  # not reducing: only the suitability factor
    open_ = E.shape(G, s, 50.0, d_new, np.ones(2), 0.0, 10.0, 60.0)
    np.testing.assert_allclose(open_, G * (1 + s))
    dense = E.shape(G, s, 50.0, d_new, np.ones(2), 0.3, 10.0, 60.0)
    np.testing.assert_allclose(dense, G * (1 + 2 * s ** 2 * 0.6))
    red = E.shape(G, s, 50.0, np.array([49.0, 49.0]), np.ones(2), 0.0, 10.0, 60.0)
    np.testing.assert_allclose(red, G * (1 + s) * 2.0 * (1 + 1.5 * s))  # full progress: bonus 2
    assert E.journey_bonus(0.0, 100.0) == pytest.approx(3.0) and E.journey_bonus(5.0, 100.0) == pytest.approx(2.0)
    assert E.journey_bonus(50.0, 100.0) == 1.0
    assert [E.ranking_weights(x) for x in (0.9, 0.7, 0.5)] == [(0.7, 0.3), (0.6, 0.4), (0.5, 0.5)]
    score, order = E.rank(np.array([0.9, 0.8]), np.array([-1.0, -3.0]), 0.9)
    np.testing.assert_allclose(score, [0.7 * 0.9, 0.7 * 0.8 + 0.3])
    assert list(order) == [1, 0]


def test_plan_in_open_space_heads_for_the_target_and_steps_at_least_1m():
    rng = np.random.default_rng(0)
    pos, tgt = np.array([0.0, 0, 5]), np.array([0.0, 40, 5])
    S_now = suitability(10.0, 0.0)
    res = plan_waypoints(pos, tgt, np.zeros((0, 3)), 10.0, 0.0, S_now, 6.0, 40.0, rng)
    assert len(res.actions) == policy_length(S_now)
    assert (np.linalg.norm(res.actions - pos, axis=1) >= 1.0).all()
    first = res.actions[0] - pos
    assert first[1] / np.linalg.norm(first) > 0.9 and res.rule == "threshold 0.75"
    assert res.efe_us_per_candidate > 0
    # a wall of voxels across the direct path: the first action avoids it
    xs, zs = np.meshgrid(np.arange(-6, 6.01, 0.15), np.arange(0, 10.01, 0.15))
    wall = np.stack([xs.ravel(), np.full(xs.size, 4.0), zs.ravel()], 1)
    no_filter = plan_waypoints(pos, tgt, wall, 4.0, 0.0, suitability(4.0, 0.0), 6.0, 40.0,
                               np.random.default_rng(0), DronePlannerConfig(use_filter=False))
    n_ring = round(0.7 * waypoint_count(suitability(4.0, 0.0), 0.0, 4.0, 40.0))
    # every distinct candidate is kept; the ring's repeated up/down points are scored once
    assert no_filter.rule == "no filter" and no_filter.n_kept == no_filter.n_candidates - 2 * (n_ring - 1)


def test_lookahead_adds_the_best_continuation_and_prunes_blocked_segments():
    from cogmap.genmodel.suitability import clearance, density
    from cogmap.planning.drone_lookahead import LookaheadConfig, _segment_distance, plan_sequence

    pos, tgt = np.array([0.0, 0, 5]), np.array([0.0, 40, 5])
    s_now = suitability(10.0, 0.0)
    V0 = np.zeros((0, 3))
    res, values = plan_sequence(pos, tgt, V0, 10.0, 0.0, s_now, 6.0, 40.0, np.random.default_rng(0),
                                lookahead=LookaheadConfig(depth=2))
    w1 = res.actions[0]
    np.testing.assert_allclose(w1, [0.0, waypoint_radius(s_now, 0.0, 10.0, 40.0), 5.0], atol=1e-9)  # direct step
    d1 = clearance(w1, V0)
    nxt = plan_waypoints(w1, tgt, V0, d1, density(w1, V0), suitability(d1, 0.0), 6.0, 40.0, np.random.default_rng(5))
    assert values[0] == pytest.approx(res.efe[0] + nxt.efe[0])
    assert _segment_distance(np.zeros(3), np.array([4.0, 0, 0]), np.array([[2.0, 0.3, 0]])) == pytest.approx(0.3)
    # a thin pole right on the direct path: the direct step is pruned even though its end point is clear
    pole = np.stack([np.zeros(20), np.full(20, 1.0), np.linspace(0, 9, 20)], 1)
    d_obs = clearance(pos, pole)
    blocked, _ = plan_sequence(pos, tgt, pole, d_obs, density(pos, pole), suitability(d_obs, 0.0), 6.0, 40.0,
                               np.random.default_rng(0), lookahead=LookaheadConfig(depth=2))
    assert all(_segment_distance(pos, w, pole) >= 0.5 for w in blocked.actions)


def test_drone_efe_is_the_objective_of_its_two_terms():
    rng = np.random.default_rng(3)
    pref, bonus, m, eta = rng.random(30), rng.random(30), 5 * rng.random(30), rng.random(30)
    G, prag, epi = E.efe(pref, bonus, m, 6.0, 1.0, 0.2, eta)
    ctx = E.DroneStep(pref, bonus, m * eta, 6.0)
    obj = E.drone_objective(1.0, 0.2)
    assert obj.names == ("drone_pragmatic", "drone_epistemic")
    np.testing.assert_array_equal(G, obj(ctx))
    # the closed form, DRONE.md 2.5 (to rounding: the factors are multiplied in another order)
    np.testing.assert_allclose(prag, -(pref + bonus) * m * eta, rtol=1e-15)
    np.testing.assert_allclose(epi, -0.2 * 0.5 * 6.0 * m * eta, rtol=1e-15)
    # a user's objective (here without the epistemic term) replaces the weights
    G_prag, _, e0 = E.efe(pref, bonus, m, 6.0, 1.0, 0.2, eta, objective=E.drone_objective(1.0, 0.0))
    np.testing.assert_array_equal(G_prag, prag)
    assert (e0 == 0).all()


@pytest.mark.parametrize("depth", [1, 2])
def test_the_drone_planner_of_the_registry_is_the_one_step_ranking_or_the_lookahead(depth):
    from cogmap.genmodel.drone_beliefs import KernelBeliefModel, entropy
    from cogmap.inference import get
    from cogmap.planning.drone_lookahead import LookaheadConfig, plan_sequence
    from cogmap.planning.drone_planner import DroneScene
    from cogmap.planning.planners import PlanSettings, accepting_planners, get_planner

    pos, tgt = np.array([0.0, 0, 5]), np.array([0.0, 40, 5])
    pole = np.stack([np.zeros(20), np.full(20, 1.0), np.linspace(0, 9, 20)], 1)
    from cogmap.genmodel.suitability import clearance, density

    d_obs, rho = clearance(pos, pole), density(pos, pole)
    s_now = suitability(d_obs, rho)
    beliefs, _ = get("kernel")(KernelBeliefModel(), None, [{"distance": 40.0, "azimuth": 0.0, "elevation": 0.0,
                                                            "suitability": s_now, "density": rho}])
    h = entropy(beliefs[0]) + entropy(beliefs[1]) + entropy(beliefs[2])
    scene = DroneScene(pos, tgt, pole, d_obs, rho, s_now, 40.0, np.zeros((0, 3)), DronePlannerConfig())
    assert accepting_planners(scene) == ("drone",)
    plan = get_planner("drone")(scene, beliefs, None, PlanSettings(policy_len=depth, rng=np.random.default_rng(0)))
    if depth == 1:
        ref = plan_waypoints(pos, tgt, pole, d_obs, rho, s_now, h, 40.0, np.random.default_rng(0))
        values = ref.efe
    else:
        ref, values = plan_sequence(pos, tgt, pole, d_obs, rho, s_now, h, 40.0, np.random.default_rng(0),
                                    lookahead=LookaheadConfig(depth=2))
    np.testing.assert_array_equal(plan.action, ref.actions[0])
    np.testing.assert_array_equal(plan.policies, ref.actions)
    np.testing.assert_array_equal(plan.G, values)
    with pytest.raises(ValueError, match="needs settings.rng"):
        get_planner("drone")(scene, beliefs, None, PlanSettings(policy_len=depth))

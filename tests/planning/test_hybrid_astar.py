"""Hybrid A* with the safety term on hand-made worlds whose LiDAR is cast analytically."""

import math

import numpy as np
import pytest

from cogmap.genmodel.numerics import wrap_angle
from cogmap.planning.hybrid_astar import (
    HybridAStarConfig,
    SafetyTerm,
    cost_grid,
    holonomic_cost_to_go,
    plan_path,
    rollout,
)

N_BEAMS, RANGE = 20, 0.53


def segment_scan(segments):
    """A scan function for walls given as segments ``(x0, y0, x1, y1)``: exact ray-segment casts."""
    seg = np.asarray(segments, float)
    a, d = seg[:, :2], seg[:, 2:] - seg[:, :2]

    def scan(poses):
        poses = np.asarray(poses, float)
        ang = poses[:, 2:3] + 2 * np.pi * np.arange(N_BEAMS) / N_BEAMS  # (K, B)
        r = np.stack([np.cos(ang), np.sin(ang)], -1)[:, :, None, :]  # (K, B, 1, 2)
        o = poses[:, None, None, :2]
        w = a[None, None] - o  # (K, 1, S, 2)
        den = r[..., 0] * d[..., 1] - r[..., 1] * d[..., 0]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (w[..., 0] * d[..., 1] - w[..., 1] * d[..., 0]) / den
            u = (w[..., 0] * r[..., 1] - w[..., 1] * r[..., 0]) / den
        hit = (np.abs(den) > 1e-12) & (t >= 0) & (u >= 0) & (u <= 1)
        return np.minimum(np.where(hit, t, np.inf).min(-1), RANGE)

    return scan


BOX = [(0, 0, 1, 0), (1, 0, 1, 1), (1, 1, 0, 1), (0, 1, 0, 0)]
CORRIDOR = [(0, 0.4, 1, 0.4), (0, 0.6, 1, 0.6), (0, 0.4, 0, 0.6), (1, 0.4, 1, 0.6)]


def crosses(p, q, seg) -> bool:
    """Does the segment p-q properly cross wall segment ``seg``?"""
    def orient(a, b, c):
        return np.sign((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))

    a, b = np.array(seg[:2]), np.array(seg[2:])
    return orient(p, q, a) * orient(p, q, b) < 0 and orient(a, b, p) * orient(a, b, q) < 0


def test_safety_term_matches_appendix_c():
    s = SafetyTerm()
    x = np.array([0.0, 0.03, 0.05, 0.1, 0.53])
    expected = 1e4 / (1 + np.exp((x - 0.03) * 1e2))
    assert np.allclose([s(v[None]) for v in x], expected, rtol=1e-12)
    assert s(np.array([0.03, 0.03])) == pytest.approx(1e4)  # mu / 2 per beam at the threshold
    assert np.isfinite(s(np.array([-10.0, 100.0])))


def test_straight_corridor_path_is_the_straight_line():
    scan = segment_scan(CORRIDOR)
    plan = plan_path([0.1, 0.5, 0.0], [0.9, 0.5, 0.0], scan, 1.0)
    assert plan.found, plan.reason
    assert plan.length == pytest.approx(0.8, abs=1e-9)
    assert np.allclose(plan.poses[:, 1], 0.5, atol=1e-9)
    assert np.allclose(plan.poses[-1], [0.9, 0.5, 0.0], atol=1e-9)
    # the plan's poses are the engineered transition applied to its controls
    assert np.allclose(rollout([0.1, 0.5, 0.0], plan.controls), plan.poses)


def test_wall_forces_a_detour():
    wall = (0.5, 0.0, 0.5, 0.7)
    scan = segment_scan([*BOX, wall])
    start, goal = np.array([0.25, 0.25, 0.0]), np.array([0.75, 0.25, 0.0])
    plans = {h: plan_path(start, goal, scan, 1.0, HybridAStarConfig(step=0.04, cell=0.025, heuristic=h))
             for h in ("grid", "euclid")}
    for plan in plans.values():
        assert plan.found, plan.reason
        shortest = 2 * math.hypot(0.25, 0.45)  # around the wall's tip at (0.5, 0.7)
        assert shortest < plan.length < 1.5 * shortest
        assert max(plan.poses[:, 1]) > 0.7  # it went round the end of the wall
        for p, q in zip(plan.poses[:-1], plan.poses[1:], strict=True):
            assert not crosses(p[:2], q[:2], wall)
        # the safety term keeps the path off the wall's tip
        tip = np.hypot(plan.poses[:, 0] - 0.5, plan.poses[:, 1] - 0.7)
        assert tip.min() > 0.05
    # the holonomic-with-obstacles heuristic expands fewer nodes than the straight-line one, at a
    # cost close to that of the admissible search
    assert plans["grid"].expansions < plans["euclid"].expansions
    assert plans["grid"].cost <= 1.2 * plans["euclid"].cost


def test_unreachable_goal_is_a_clear_failure():
    pen = [(0.6, 0.6, 0.9, 0.6), (0.9, 0.6, 0.9, 0.9), (0.9, 0.9, 0.6, 0.9), (0.6, 0.9, 0.6, 0.6)]
    scan = segment_scan([*BOX, *pen])
    cfg = HybridAStarConfig(step=0.05, cell=0.03, heading_bins=2)
    plan = plan_path([0.2, 0.2, 0.0], [0.75, 0.75, 0.0], scan, 1.0, cfg)
    assert not plan.found
    assert "unreachable" in plan.reason
    assert plan.controls.shape == (0, 2) and math.isnan(plan.length)
    budget = plan_path([0.2, 0.2, 0.0], [0.75, 0.75, 0.0], scan, 1.0,
                       HybridAStarConfig(step=0.05, cell=0.03, heading_bins=4, max_expansions=5))
    assert not budget.found and "budget" in budget.reason and budget.expansions == 5


def test_heading_wraps_across_pi():
    scan = segment_scan(CORRIDOR)
    start = [0.9, 0.5, math.pi]  # facing -x; stored as -pi
    goal = [0.2, 0.5, math.pi - 0.1]  # facing -x, 0.1 short of +pi
    plan = plan_path(start, goal, scan, 1.0)
    assert plan.found, plan.reason
    assert plan.length == pytest.approx(0.7, abs=1e-9)
    assert np.all(np.abs(plan.controls[:, 0]) <= math.pi)
    assert np.allclose(plan.controls[:-1, 0], 0.0, atol=1e-9)  # straight along -x
    # the last turn goes the short way across the +-pi seam: -0.1, not +6.18
    assert plan.controls[-1, 0] == pytest.approx(-0.1, abs=1e-9)
    assert np.all((plan.poses[:, 2] >= -math.pi) & (plan.poses[:, 2] < math.pi))
    assert float(wrap_angle(plan.poses[-1, 2] - goal[2])) == pytest.approx(0.0, abs=1e-9)


def test_holonomic_grid_blocks_walls():
    scan = segment_scan([*BOX, (0.5, 0.0, 0.5, 1.0)])  # a wall that splits the box
    grid = cost_grid(scan, 1.0, 0.05)
    h = holonomic_cost_to_go(grid, [0.75, 0.5], HybridAStarConfig(step=0.05, cell=0.03))
    assert np.isfinite(h[15, 10]) and np.isinf(h[5, 10])


def test_bad_inputs():
    scan = segment_scan(BOX)
    with pytest.raises(ValueError, match="outside"):
        plan_path([1.5, 0.5, 0], [0.5, 0.5, 0], scan, 1.0)
    with pytest.raises(ValueError, match="cell diagonal"):
        HybridAStarConfig(step=0.02, cell=0.02)
    with pytest.raises(ValueError, match="heuristic"):
        HybridAStarConfig(heuristic="manhattan")
    with pytest.raises(ValueError, match="scan_fn"):
        plan_path([0.5, 0.5, 0], [0.6, 0.5, 0], lambda p: np.ones(3), 1.0)

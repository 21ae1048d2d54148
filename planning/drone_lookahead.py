"""Deeper drone planning: the same EFE over depth-2 and depth-3 waypoint sequences (beyond the paper).

The paper flies the first action of a one-step ranking (its stated limit). Here a sequence
w1 -> w2 -> ... is scored by the sum of the shaped EFE of its steps, each step planned by
:func:`~cogmap.planning.drone_planner.plan_waypoints` from the predicted position with the
perception predicted there from the same voxels (clearance, density and suitability at the
waypoint, so the current clearance no longer caps the later steps). Enumeration with pruning: each
level keeps only the planner's own top-K actions (K = round(5 - 3 S), at most ``beam``), so depth 2
costs about K + 1 planning steps and depth 3 about K^2 + K + 1. First actions are then ranked with
the paper's rule (w_S S + w_E (1 - normalised value)) on the sequence value instead of the one-step
EFE. A step whose straight segment passes within ``segment_margin`` of a voxel is pruned (the
one-step planner scores end points only, so it cannot see a trunk between the drone and a clear
waypoint); if every first action is pruned, the one-step choice stands.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cogmap.genmodel.suitability import clearance, density, suitability

from .drone_efe import rank
from .drone_planner import DronePlannerConfig, PlanResult, plan_waypoints


@dataclass(frozen=True)
class LookaheadConfig:
    depth: int = 2
    beam: int = 5
    discount: float = 1.0
    segment_margin: float = 0.5  # m: drone radius 0.25 m plus a margin


def _segment_distance(a, b, V) -> float:
    """Smallest distance from the segment a -> b to any voxel (inf without voxels)."""
    if len(V) == 0:
        return float("inf")
    ab = b - a
    L2 = max(float(ab @ ab), 1e-12)
    t = np.clip((V - a) @ ab / L2, 0.0, 1.0)
    return float(np.sqrt((((V - a) - t[:, None] * ab) ** 2).sum(1).min()))


def _value(pos, tgt, V, entropy_sum, d_start, rng, cfg, look, depth, visited, objective) -> float:
    """Best discounted sum of shaped EFE over ``depth`` more steps from ``pos`` (lower is better);
    ``visited`` holds the positions visited before ``pos`` (the sequence's own earlier steps included)."""
    d_obs = clearance(pos, V)
    rho = density(pos, V)
    s = float(suitability(d_obs, rho))
    if np.linalg.norm(tgt - pos) <= 1.5:
        return 0.0
    res = plan_waypoints(pos, tgt, V, d_obs, rho, s, entropy_sum, d_start, rng, cfg, visited, objective)
    best = 0.0
    for w, g in zip(res.actions[: look.beam], res.efe[: look.beam], strict=False):
        if _segment_distance(pos, w, V) < look.segment_margin:
            continue
        v = float(g)
        if depth > 1:
            v += look.discount * _value(w, tgt, V, entropy_sum, d_start, rng, cfg, look, depth - 1,
                                        np.vstack([visited, pos]), objective)
        best = min(best, v)
    return best


def plan_sequence(position, target, voxels, d_obs: float, rho: float, s_now: float, entropy_sum: float,
                  d_start: float, rng: np.random.Generator, config: DronePlannerConfig | None = None,
                  lookahead: LookaheadConfig | None = None, visited=None,
                  objective=None) -> tuple[PlanResult, np.ndarray]:
    """One decision with lookahead; returns the one-step :class:`PlanResult` reordered by sequence
    value (the first action is the one to fly) and the sequence values of its actions. ``visited``
    (K, 3): positions of the episode's earlier decisions (the novelty of the epistemic term); each
    sequence step also counts the sequence's earlier positions as visited."""
    cfg = config or DronePlannerConfig()
    look = lookahead or LookaheadConfig()
    pos = np.asarray(position, float)
    tgt = np.asarray(target, float)
    V = np.asarray(voxels, float).reshape(-1, 3)
    visited = np.zeros((0, 3)) if visited is None else np.asarray(visited, float).reshape(-1, 3)
    first = plan_waypoints(pos, tgt, V, d_obs, rho, s_now, entropy_sum, d_start, rng, cfg, visited, objective)
    n = min(len(first.actions), look.beam)
    values = np.zeros(n)
    ok = np.ones(n, bool)
    for i in range(n):
        w = first.actions[i]
        ok[i] = _segment_distance(pos, w, V) >= look.segment_margin
        values[i] = float(first.efe[i])
        if look.depth > 1:
            values[i] += look.discount * _value(w, tgt, V, entropy_sum, d_start, rng, cfg, look, look.depth - 1,
                                                np.vstack([visited, pos]), objective)
    if not ok.any():
        return first, values
    idx = np.flatnonzero(ok)
    _, order = rank(first.suitability[idx], values[idx], s_now)
    sel = idx[order]
    res = PlanResult(first.actions[sel], first.scores[sel], first.efe[sel], first.suitability[sel], first.radius,
                     first.n_candidates, first.n_kept, first.rule, first.efe_us_per_candidate)
    return res, values[sel]

"""Study metrics beyond :mod:`cogmap.metrics`: endpoints (CE and nAUC at 90 % coverage and at the
end of a run), interventions and success, drift, the three path-length ratios of Table 5,
transition beliefs into a node (Figure 8), run digests, summaries.

Definitions (stated once, used by every study):

* **curve**: ``distance[i]``, ``coverage[i]`` = distance travelled before decision ``i`` and the
  LiDAR coverage seen by then (the episode lists; the last entry is after the last move).
* **endpoint at 90 %**: the first sample ``i90`` with ``coverage >= 0.9``.
  ``CE@90 = coverage[i90] * free_area / distance[i90]`` (area covered then / distance then; None
  when the run never reaches 90 % or reaches it before moving). ``nAUC@90`` = the nAUC over the
  fixed budget (below) of the curve cut at ``i90``: coverage follows the run up to ``i90`` and
  holds ``coverage[i90]`` after it, so what a method does after reaching 90 % does not count.
* **endpoint at the end**: the last sample. ``CE = area covered / distance`` and ``nAUC`` over the
  budget with the last coverage held.
* **nAUC budget**: the distance a robot sweeping a 2 m wide swath needs for the free area,
  ``free_area / 2`` metres (environment-dependent, method-independent).
* **interventions** (the paper counts trials that needed a human, section 4.2 and Appendix D.3:
  stuck, collision, non-recoverable map overlap); nobody intervenes here, we count the moments a
  human would have stepped in (:class:`SuccessRule`). A run that levels off (moves without
  coverage gain) is not a failure. **success** = no intervention.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import asdict, dataclass

import numpy as np

from cogmap.metrics import ate_per_metre, nauc, rmse

NAUC_SWATH_M = 2.0
COVERAGE_LEVEL = 0.9  # the paper's AIMAPP levels off near 90 % (section 4.2)


def nauc_budget(free_area_m2: float, swath_m: float = NAUC_SWATH_M) -> float:
    return float(free_area_m2) / swath_m


def nauc_over_budget(distances, coverages, budget: float) -> float:
    """:func:`cogmap.metrics.nauc` over ``[0, budget]`` (the run's last coverage is held)."""
    return nauc(distances, coverages, budget)


def first_reach(coverages, level: float = COVERAGE_LEVEL) -> int | None:
    """Index of the first sample with coverage >= ``level`` (None if never)."""
    hit = np.flatnonzero(np.asarray(coverages, float) >= level)
    return int(hit[0]) if hit.size else None


def endpoint(distances, coverages, free_area_m2: float, budget: float, index: int) -> dict:
    """CE and nAUC of the curve cut at sample ``index`` (coverage held after it)."""
    d = np.asarray(distances, float)[: index + 1]
    c = np.asarray(coverages, float)[: index + 1]
    dist, cov = float(d[-1]), float(c[-1])
    return {"coverage": cov, "distance_m": dist, "area_m2": cov * free_area_m2,
            "ce": cov * free_area_m2 / dist if dist > 0 else None, "nauc": nauc(d, c, budget)}


def endpoints(distances, coverages, free_area_m2: float, budget: float, level: float = COVERAGE_LEVEL) -> dict:
    """``{"end": ..., "at_level": ... or None, "level_index": i or None}`` (see the module docstring)."""
    i = first_reach(coverages, level)
    last = len(distances) - 1
    return {"end": endpoint(distances, coverages, free_area_m2, budget, last),
            "at_level": None if i is None else endpoint(distances, coverages, free_area_m2, budget, i),
            "level_index": i}


@dataclass(frozen=True)
class SuccessRule:
    """When a run would have needed a human (paper section 4.2, Appendix D.3).

    * **stuck**: for ``stuck_decisions`` consecutive decisions the true position stays within
      ``stuck_radius_m`` of where that stretch began (spinning or waiting in place, or pushing
      against something; a level-off walks between places and is not stuck).
    * **collision**: ``collision_run`` consecutive failed moves. Our simulator stops every move
      before contact and reports it failed, and the methods recover from a single failure by
      their own rules (AIMAPP learns the transition is impossible, Table 7; the frontier
      explorers blacklist a goal after 3 failures, mark bumper hits and re-plan). A human steps
      in when the robot keeps driving into what it does not see (the paper's LiDAR blind spots:
      "the robot collided or spun in place"): five failures in a row, more than any method's own
      recovery allows.
    * **map mismatch**: the believed position is more than ``mismatch_m`` from the true one for
      ``mismatch_decisions`` consecutive decisions ("non-recoverable map overlap"). ``mismatch_m``
      None means the agent's influence radius (1 m small rooms, 2 m large ones): beyond the spacing
      of its places the robot files what it sees under the wrong place.
    """

    stuck_decisions: int = 15
    stuck_radius_m: float = 0.25
    collision_run: int = 5
    mismatch_m: float | None = None
    mismatch_decisions: int = 10

    def to_dict(self) -> dict:
        return asdict(self)


def interventions(true_xy, moved, belief_xy, rule: SuccessRule, mismatch_m: float | None = None) -> list[dict]:
    """Moments a human would have stepped in: ``[{"cause": "stuck"|"collision"|"map", "step": i}]``.

    ``true_xy[i]``, ``belief_xy[i]``: positions at decision ``i``; ``moved[i]``: outcome of the move
    before decision ``i`` (None for the first). Counting restarts after each event (nobody
    actually steps in, so a robot that stays stuck is counted again after another stretch).
    ``mismatch_m`` overrides ``rule.mismatch_m`` (e.g. the resolved influence radius). Belief rows
    that are not finite (no belief) never count as a mismatch."""
    t = np.asarray(true_xy, float).reshape(-1, 2)
    b = np.asarray(belief_xy, float).reshape(-1, 2)
    bound = rule.mismatch_m if mismatch_m is None else mismatch_m
    if bound is None:
        raise ValueError("a map-mismatch bound is needed (rule.mismatch_m or mismatch_m)")
    events = []
    anchor, fails, far = 0, 0, 0
    for i in range(len(t)):
        if np.hypot(*(t[i] - t[anchor])) > rule.stuck_radius_m:
            anchor = i
        elif i - anchor >= rule.stuck_decisions:
            events.append({"cause": "stuck", "step": i})
            anchor = i
        fails = fails + 1 if moved[i] is False else 0
        if fails >= rule.collision_run:
            events.append({"cause": "collision", "step": i})
            fails = 0
        err = float(np.hypot(*(b[i] - t[i])))
        far = far + 1 if math.isfinite(err) and err > bound else 0
        if far >= rule.mismatch_decisions:
            events.append({"cause": "map", "step": i})
            far = 0
    return events


def trajectory_digest(true_xy, decimals: int = 3) -> str:
    """SHA-256 (16 hex) of the true trajectory rounded to ``decimals`` (mm): equal digests mean
    the same run twice."""
    t = np.round(np.asarray(true_xy, float).reshape(-1, 2), decimals) + 0.0  # no negative zero
    return hashlib.sha256(json.dumps(t.tolist()).encode()).hexdigest()[:16]


def duplicates(digests: dict) -> list[list]:
    """Groups of names sharing a digest (``{name: digest}`` -> ``[[name, name], ...]``)."""
    by: dict = {}
    for name, d in digests.items():
        by.setdefault(d, []).append(name)
    return [sorted(v) for v in by.values() if len(v) > 1]


def drift_metrics(truth, odometry, belief) -> dict:
    """RMSE (m) and ATE per metre of the believed and the odometry positions."""
    t, o, b = (np.asarray(x, float)[:, :2] for x in (truth, odometry, belief))
    ok = np.all(np.isfinite(t), 1) & np.all(np.isfinite(o), 1) & np.all(np.isfinite(b), 1)
    t, o, b = t[ok], o[ok], b[ok]
    if len(t) == 0:
        return {"rmse_belief_m": None, "rmse_odometry_m": None, "ate_per_m_belief": None, "ate_per_m_odometry": None}
    return {
        "rmse_belief_m": rmse(b, t),
        "rmse_odometry_m": rmse(o, t),
        "ate_per_m_belief": ate_per_metre(b, t),
        "ate_per_m_odometry": ate_per_metre(o, t),
    }


def _ratio(a, b):
    if a is None or b is None or not (math.isfinite(a) and math.isfinite(b)) or b <= 0:
        return None
    return float(a / b)


def path_length_ratios(executed_m: float, astar_m: float, plan_m: float) -> dict:
    """Table 5: executed vs A* on the occupancy grid, executed vs the agent's own graph plan,
    agent plan vs A*. (executed / A* = (executed / plan) * (plan / A*).)"""
    return {
        "plr_executed_vs_astar": _ratio(executed_m, astar_m),
        "plr_executed_vs_plan": _ratio(executed_m, plan_m),
        "plr_plan_vs_astar": _ratio(plan_m, astar_m),
    }


def graph_plan_length(transitions, poses, start: int, goals, threshold: float = 0.5) -> float:
    """Length (m) of the shortest plan on the agent's graph (A* over transitions believed
    possible, edges weighted by the distance between stored poses) to the nearest goal."""
    from cogmap.planning.astar import astar_graph

    best = math.inf
    for g in np.atleast_1d(goals):
        _, cost = astar_graph(transitions, int(start), int(g), poses=poses, threshold=threshold)
        best = min(best, float(cost))
    return best


def transitions_into(succ, prob, node: int, n: int) -> dict:
    """Believed probabilities of moving into ``node`` from any other state (sparse padded
    successor lists ``succ``/``prob`` of shape (capacity, actions, slots))."""
    s, p = np.asarray(succ)[:n], np.asarray(prob)[:n]
    src = np.broadcast_to(np.arange(n)[:, None, None], s.shape)
    mask = (s == node) & (src != node) & (p > 0)
    vals = p[mask]
    return {"max": float(vals.max()) if vals.size else 0.0, "mean": float(vals.mean()) if vals.size else 0.0,
            "count": int(vals.size), "above_half": int((vals > 0.5).sum())}


def summarise(values) -> dict:
    """Mean, std (population), median and count of the finite values."""
    v = np.asarray([x for x in values if x is not None and np.isfinite(x)], float)
    if v.size == 0:
        return {"mean": None, "std": None, "median": None, "n": 0}
    return {"mean": float(v.mean()), "std": float(v.std()), "median": float(np.median(v)), "n": int(v.size)}


def fraction_within(ratios, limit: float) -> float | None:
    v = [r for r in ratios if r is not None]
    return float(np.mean(np.asarray(v) <= limit)) if v else None

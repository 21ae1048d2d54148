"""Study metrics beyond :mod:`cogmap.metrics`: interventions and success, drift, the three
path-length ratios of Table 5, transition beliefs into a node (Figure 8), summaries.

Definitions (stated once, used by every study):

* **stall / intervention**: ``fail_run`` consecutive failed moves (a failed move is a
  collision: the motion stopped before reaching its waypoint), or ``nogain_run`` consecutive
  decisions adding less than ``min_gain`` coverage while coverage is below ``target``.
  Counting restarts after each stall. The paper counts human interventions; we count the
  situations in which a human would have stepped in, without stepping in.
* **success**: final coverage >= ``coverage`` and no stall.
* **nAUC budget**: the distance a robot sweeping a 2 m wide swath needs for the free area,
  ``free_area / 2`` metres (environment-dependent, method-independent).
"""

from __future__ import annotations

import math

import numpy as np

from cogmap.metrics import ate_per_metre, nauc, rmse

NAUC_SWATH_M = 2.0


def nauc_budget(free_area_m2: float, swath_m: float = NAUC_SWATH_M) -> float:
    return float(free_area_m2) / swath_m


def nauc_over_budget(distances, coverages, budget: float) -> float:
    """:func:`cogmap.metrics.nauc` over ``[0, budget]`` (the run's last coverage is held)."""
    return nauc(distances, coverages, budget)


def count_stalls(moved, coverage, fail_run: int = 5, nogain_run: int = 25, min_gain: float = 1e-3,
                 target: float = 0.99) -> int:
    """Number of stalls in a run. ``moved[i]`` is the outcome of the move before decision i
    (None for the first), ``coverage[i]`` the coverage at decision i."""
    stalls, fails, flat = 0, 0, 0
    prev = None
    for m, c in zip(moved, coverage, strict=False):
        fails = fails + 1 if m is False else 0
        if prev is not None and c - prev < min_gain and c < target:
            flat += 1
        else:
            flat = 0
        prev = c
        if fails >= fail_run or flat >= nogain_run:
            stalls += 1
            fails, flat = 0, 0
    return stalls


def is_success(final_coverage: float, stalls: int, coverage: float = 0.9) -> bool:
    return bool(final_coverage >= coverage and stalls == 0)


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

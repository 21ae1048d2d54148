"""Hybrid A* for a point agent that turns, then moves along its heading (DVBF-LM paper Section V-A).

The search runs over a discretisation of poses ``(x, y, heading)`` into cells of side ``cell`` and
``heading_bins`` heading bins; every cell keeps the continuous pose with which it was first reached
at its best cost (Dolgov et al.'s hybrid A*, the paper's reference [5]). A node is expanded with
discrete motion primitives: turn by ``2 pi k / n_beams`` (``k`` in ``turns``), then move ``step``
forward. Successor poses follow the engineered transition (rotate, then translate).

Everything the planner knows about the world comes from ``scan_fn(poses (K, 3)) -> ranges
(K, n_beams)``: beam ``k`` at heading ``+ 2 pi k / n_beams``, the maze LiDAR's convention. The same
planner thus runs (a) in a learned DVBF-LM (ranges predicted by the emission from the learned map)
and (b) in the true simulator (ray casts). As in the paper's navigation transition (Section V-B a),
a primitive is feasible when the reading along its direction exceeds the step length; because the
turns are beam directions, one scan at the current pose tells which primitives are free.

Edge weight (Section V-A, Appendix C-A): travelled distance plus the safety term of the successor,
``L_safe = sum_i s(l_i)``, ``s(x) = mu / (1 + exp((x - delta) sigma))``, ``mu = 1e4``,
``delta = 0.03``, ``sigma = 1e2``, over the successor's readings ``l_i``.

Heuristic: Dolgov's "holonomic with obstacles" cost-to-go, a Dijkstra search from the goal over a
grid of position cells whose edge costs use the same scan function (length plus the safety term
per ``step`` of travel); ``euclid`` (straight-line distance, admissible) is the other choice. The
heuristic is weighted (``heuristic_weight``, weighted A*), so plans are near-optimal, not optimal.
When an expanded node lies within ``shot_radius`` of the goal and the reading toward the goal
clears the remaining distance, a straight shot ends the search (the analytic expansion of hybrid
A*); a last pure rotation turns the agent to the goal heading.

Pure numpy/scipy; no agent-layer import.
"""

from __future__ import annotations

import heapq
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from cogmap.genmodel.numerics import wrap_angle

ScanFn = Callable[[np.ndarray], np.ndarray]


@dataclass(frozen=True)
class SafetyTerm:
    """Appendix C-A: ``s(x) = mu / (1 + exp((x - delta) * sigma))``, summed over the beams."""

    mu: float = 1e4
    delta: float = 0.03
    sigma: float = 1e2

    def __call__(self, ranges) -> np.ndarray:
        """``L_safe = sum_i s(l_i)`` over the last axis of ``ranges``."""
        x = np.asarray(ranges, float)
        # mu * sigmoid(-(x - delta) sigma), written with tanh to stay finite for any x
        s = 0.5 * self.mu * (1.0 - np.tanh(0.5 * (x - self.delta) * self.sigma))
        return s.sum(-1)


@dataclass(frozen=True)
class HybridAStarConfig:
    """Planner settings.

    ``step``: forward length of every primitive; ``turns``: allowed turns as beam indices (turn
    ``2 pi k / n_beams``; ``None``: every beam direction); ``cell`` and ``heading_bins``: the search
    discretisation; ``clearance``: extra free distance a forward move needs beyond its length;
    ``shot_radius``: distance to the goal from which a straight shot is tried (default ``2 * step``);
    ``heuristic``: ``"grid"`` (holonomic with obstacles) or ``"euclid"``; ``heuristic_weight``: weighted
    A* factor on the heuristic (1: plain A*; 1.5 by default: on maze 1 it cut the expansions of long
    plans about tenfold at costs within 5 %); ``max_expansions``: search budget; ``turn_heading``: end
    with a rotation to the goal heading."""

    step: float = 0.025
    turns: tuple[int, ...] | None = None
    cell: float = 0.015
    heading_bins: int = 20
    clearance: float = 0.0
    shot_radius: float | None = None
    safety: SafetyTerm = SafetyTerm()
    heuristic: str = "grid"
    heuristic_weight: float = 1.5
    max_expansions: int = 20000
    turn_heading: bool = True

    def __post_init__(self):
        if self.step <= 0 or self.cell <= 0 or self.heading_bins < 1 or self.max_expansions < 1:
            raise ValueError(f"HybridAStarConfig: step, cell, heading_bins, max_expansions must be positive: {self}")
        if self.step <= math.sqrt(2) * self.cell:  # else a primitive can end in its own, closed, cell
            raise ValueError(f"HybridAStarConfig: step ({self.step}) must exceed the cell diagonal "
                             f"sqrt(2) * cell ({math.sqrt(2) * self.cell:.4g}) so every move leaves its cell")
        if self.clearance < 0:
            raise ValueError(f"HybridAStarConfig: clearance must be >= 0, got {self.clearance}")
        if self.heuristic_weight < 1:
            raise ValueError(f"HybridAStarConfig: heuristic_weight must be >= 1, got {self.heuristic_weight}")
        if self.heuristic not in ("grid", "euclid"):
            raise ValueError(f"HybridAStarConfig: heuristic must be 'grid' or 'euclid', got {self.heuristic!r}")

    @property
    def shot(self) -> float:
        return 2.0 * self.step if self.shot_radius is None else float(self.shot_radius)


class Plan(NamedTuple):
    """Result of :func:`plan_path`. ``controls (T, 2)`` rows ``(turn, forward)``; ``poses (T + 1, 3)``
    the poses the plan predicts (engineered transition); ``length``: travelled distance; ``cost``:
    length plus the safety terms; ``expansions``: nodes expanded; ``queries``: poses passed to the
    scan function (the planner's "simulation steps", Figure 6c); ``found``: a plan reached the goal;
    ``reason``: why not, when not."""

    found: bool
    controls: np.ndarray
    poses: np.ndarray
    length: float
    cost: float
    expansions: int
    queries: int
    seconds: float
    reason: str = ""


class CostGrid(NamedTuple):
    """Per-cell scans for the holonomic heuristic: ``ranges (n, n, n_beams)`` at cell centres with
    heading 0 (beam ``k`` along ``2 pi k / n_beams``), ``cell`` and ``extent`` of the square world."""

    ranges: np.ndarray
    cell: float
    extent: float


def transition(pose, control) -> np.ndarray:
    """Engineered transition: rotate by ``control[0]``, then move ``control[1]`` along the heading."""
    x, y, a = np.asarray(pose, float)
    turn, fwd = np.asarray(control, float)
    a = float(wrap_angle(a + turn))
    return np.array([x + fwd * math.cos(a), y + fwd * math.sin(a), a])


def rollout(start, controls) -> np.ndarray:
    """Poses ``(T + 1, 3)`` from applying ``controls (T, 2)`` with :func:`transition` (no walls)."""
    poses = [np.asarray(start, float)]
    for u in np.asarray(controls, float).reshape(-1, 2):
        poses.append(transition(poses[-1], u))
    return np.array(poses)


def cost_grid(scan_fn: ScanFn, extent: float, cell: float) -> CostGrid:
    """Scan every cell centre of the square ``[0, extent]^2`` once (heading 0)."""
    n = max(2, int(math.ceil(extent / cell)))
    c = (np.arange(n) + 0.5) * (extent / n)
    X, Y = np.meshgrid(c, c, indexing="ij")
    poses = np.stack([X.ravel(), Y.ravel(), np.zeros(X.size)], 1)
    ranges = np.asarray(scan_fn(poses), float).reshape(n, n, -1)
    return CostGrid(ranges, extent / n, float(extent))


def holonomic_cost_to_go(grid: CostGrid, goal_xy, config: HybridAStarConfig) -> np.ndarray:
    """Dijkstra from the goal's cell over the 8-connected cell grid: ``(n, n)`` cost-to-go (inf where
    the goal cannot be reached). An axis move is free when the beam along it clears the cell side
    (from both ends); a diagonal move when both axis routes around it are free. A move of length
    ``d`` into a cell costs ``d * (1 + L_safe(cell) / step)``: the safety term once per ``step`` of
    travel, as the search pays it."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import dijkstra

    r = grid.ranges
    n, nb = r.shape[0], r.shape[2]
    if nb % 4:
        raise ValueError(f"holonomic_cost_to_go: needs a beam count divisible by 4, got {nb}")
    h = grid.cell
    density = 1.0 + config.safety(r) / config.step  # cost per unit length in each cell
    ix, iy = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    # free axis moves: +x (beam 0), +y (beam nb/4), checked from both ends
    fx = (r[:-1, :, 0] > h) & (r[1:, :, nb // 2] > h)  # (n - 1, n): (i, j) <-> (i + 1, j)
    fy = (r[:, :-1, nb // 4] > h) & (r[:, 1:, 3 * nb // 4] > h)  # (n, n - 1): (i, j) <-> (i, j + 1)
    rows, cols, costs = [], [], []

    def add(a, b, length, mask):
        a, b = a[mask], b[mask]
        rows.extend([a, b])
        cols.extend([b, a])
        costs.extend([length * density.ravel()[b], length * density.ravel()[a]])

    idx = ix * n + iy
    add(idx[:-1, :].ravel(), idx[1:, :].ravel(), h, fx.ravel())
    add(idx[:, :-1].ravel(), idx[:, 1:].ravel(), h, fy.ravel())
    # diagonals (i, j) <-> (i + 1, j + 1) and (i + 1, j) <-> (i, j + 1)
    d1 = fx[:, :-1] & fy[1:, :] & fy[:-1, :] & fx[:, 1:]
    add(idx[:-1, :-1].ravel(), idx[1:, 1:].ravel(), math.sqrt(2) * h, d1.ravel())
    add(idx[1:, :-1].ravel(), idx[:-1, 1:].ravel(), math.sqrt(2) * h, d1.ravel())
    # edge (a -> b) costs the density of b; Dijkstra from the goal runs on the transposed graph
    g = coo_matrix((np.concatenate(costs), (np.concatenate(cols), np.concatenate(rows))), shape=(n * n, n * n))
    gi, gj = _cell(goal_xy, grid)
    return dijkstra(g.tocsr(), directed=True, indices=gi * n + gj).reshape(n, n)


def _cell(xy, grid: CostGrid) -> tuple[int, int]:
    n = grid.ranges.shape[0]
    i = min(max(int(xy[0] // grid.cell), 0), n - 1)
    j = min(max(int(xy[1] // grid.cell), 0), n - 1)
    return i, j


def _query(scan_fn: ScanFn, poses: np.ndarray) -> np.ndarray:
    out = np.asarray(scan_fn(np.asarray(poses, float)), float)
    if out.ndim != 2 or out.shape[0] != len(poses):
        raise ValueError(f"scan_fn must return (K, n_beams) ranges for K poses; got shape {out.shape}")
    return out


def plan_path(start, goal, scan_fn: ScanFn, extent: float, config: HybridAStarConfig = HybridAStarConfig(),
              grid: CostGrid | None = None) -> Plan:
    """Hybrid A* from pose ``start`` to pose ``goal`` (``(x, y, heading)``) in ``[0, extent]^2``.

    ``grid``: a :func:`cost_grid` of the same ``scan_fn`` to reuse across plans (made here when the
    heuristic is ``"grid"`` and none is given). Returns a :class:`Plan`; ``found`` is False, with the
    reason, when the goal is unreachable or the expansion budget runs out.
    """
    tic = time.perf_counter()
    start = np.asarray(start, float).reshape(3)
    goal = np.asarray(goal, float).reshape(3)
    if not (np.all(np.isfinite(start)) and np.all(np.isfinite(goal))):
        raise ValueError(f"plan_path: start and goal must be finite poses, got {start}, {goal}")
    for name, p in (("start", start), ("goal", goal)):
        if not (0 <= p[0] <= extent and 0 <= p[1] <= extent):
            raise ValueError(f"plan_path: {name} {p[:2]} lies outside [0, {extent}]^2")
    start[2], goal[2] = wrap_angle(start[2]), wrap_angle(goal[2])
    queries = 0
    s0 = _query(scan_fn, start[None])[0]
    queries += 1
    nb = s0.shape[0]
    turns = np.arange(nb) if config.turns is None else np.asarray(config.turns, int)
    if np.any((turns < 0) | (turns >= nb)):
        raise ValueError(f"plan_path: turns must be beam indices in [0, {nb}), got {config.turns}")
    turn_angles = wrap_angle(2 * np.pi * turns / nb)
    step, cell, hb = config.step, config.cell, config.heading_bins

    h_grid = None
    if config.heuristic == "grid":
        if grid is None:
            grid = cost_grid(scan_fn, extent, cell)
            queries += grid.ranges.shape[0] ** 2
        h_grid = holonomic_cost_to_go(grid, goal[:2], config)

    def heuristic(xy) -> float:
        d = math.hypot(goal[0] - xy[0], goal[1] - xy[1])
        if h_grid is None:
            return d
        v = h_grid[_cell(xy, grid)]
        return float(v) if np.isfinite(v) else d  # the coarse grid is no proof of unreachability

    def key(p) -> tuple[int, int, int]:
        hbin = int(((p[2] + np.pi) % (2 * np.pi)) / (2 * np.pi) * hb) % hb
        return int(p[0] // cell), int(p[1] // cell), hbin

    # node storage: pose, scan, g, parent index, control that led here
    poses, scans, gs, parents, ctrls = [start], [s0], [0.0], [-1], [np.zeros(2)]
    best = {key(start): 0}
    heap = [(heuristic(start), 0.0, 0)]
    closed = set()
    expansions = 0
    while heap:
        _, g, i = heapq.heappop(heap)
        k = key(poses[i])
        if k in closed or best.get(k) != i:
            continue
        closed.add(k)
        p = poses[i]
        d_goal = math.hypot(goal[0] - p[0], goal[1] - p[1])
        if d_goal <= config.shot:
            tail = _shot(p, goal, d_goal, scan_fn, config)
            queries += 1 if d_goal > 1e-12 else 0
            if tail is not None:
                return _backtrack(i, tail, poses, parents, ctrls, gs, expansions, queries, tic, start)
        if expansions >= config.max_expansions:
            return _fail(f"expansion budget of {config.max_expansions} spent without reaching the goal",
                         start, expansions, queries, tic)
        expansions += 1
        scan = scans[i]
        ok = scan[turns] > step + config.clearance  # forward reading along each primitive's direction
        if not np.any(ok):
            continue
        heads = wrap_angle(p[2] + turn_angles[ok])
        succ = np.stack([p[0] + step * np.cos(heads), p[1] + step * np.sin(heads), heads], 1)
        inside = (succ[:, 0] >= 0) & (succ[:, 0] <= extent) & (succ[:, 1] >= 0) & (succ[:, 1] <= extent)
        succ, t_idx = succ[inside], np.flatnonzero(ok)[inside]
        if not len(succ):
            continue
        s_scans = _query(scan_fn, succ)
        queries += len(succ)
        step_cost = step + config.safety(s_scans)
        for q, sc, c, t in zip(succ, s_scans, step_cost, t_idx, strict=True):
            kq = key(q)
            if kq in closed:
                continue
            gq = g + float(c)
            j = best.get(kq)
            if j is not None and gs[j] <= gq:
                continue
            poses.append(q)
            scans.append(sc)
            gs.append(gq)
            parents.append(i)
            ctrls.append(np.array([turn_angles[t], step]))
            best[kq] = len(poses) - 1
            heapq.heappush(heap, (gq + config.heuristic_weight * heuristic(q), gq, len(poses) - 1))
    return _fail(f"goal unreachable: the search closed all {expansions} reachable cells", start, expansions,
                 queries, tic)


def _shot(p, goal, dist, scan_fn, config):
    """Controls that end the plan from pose ``p``: turn toward the goal and move there if the reading
    toward it clears the distance, then (optionally) turn to the goal heading; None if blocked."""
    out = []
    heading = p[2]
    if dist > 1e-12:
        heading = math.atan2(goal[1] - p[1], goal[0] - p[0])
        r = _query(scan_fn, np.array([[p[0], p[1], heading]]))[0, 0]
        if r <= dist + config.clearance:
            return None
        out.append([float(wrap_angle(heading - p[2])), dist])
    if config.turn_heading:
        out.append([float(wrap_angle(goal[2] - heading)), 0.0])
    return np.array(out, float).reshape(-1, 2)


def _backtrack(i, tail, poses, parents, ctrls, gs, expansions, queries, tic, start) -> Plan:
    cost = gs[i] + float(np.sum(tail[:, 1]))  # the search's cost to node i plus the shot's length
    chain = []
    while parents[i] >= 0:
        chain.append(ctrls[i])
        i = parents[i]
    controls = np.concatenate([np.array(chain[::-1], float).reshape(-1, 2), tail])
    return Plan(True, controls, rollout(start, controls), float(np.sum(controls[:, 1])), cost, expansions, queries,
                time.perf_counter() - tic)


def _fail(reason, start, expansions, queries, tic) -> Plan:
    return Plan(False, np.zeros((0, 2)), np.asarray(start, float)[None], math.nan, math.nan, expansions, queries,
                time.perf_counter() - tic, reason)

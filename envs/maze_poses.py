"""Poses in a LiDAR maze: a seeded start, a grid of free poses and pairs of them, and open-loop
execution of a control sequence in the simulator, and how a navigation is judged (the DVBF-LM
studies, paper Sections V and VI)."""

from __future__ import annotations

import numpy as np

from cogmap.envs.maze import Maze
from cogmap.genmodel.numerics import wrap_angle

GRID = 5  # 5 x 5 poses per maze
SUCCESS_RADIUS = 0.05  # Section V-B b: a navigation succeeds within this distance of the goal


def start_pose(maze: Maze, seed: int) -> np.ndarray:
    """A seeded start: the centre of a random cell, a random heading (the same for every method).

    Parameters
    ----------
    maze : Maze
        The maze.
    seed : int
        Seed of the draw.

    Returns
    -------
    numpy.ndarray, shape (3,)
        ``(x, y, heading)``: a cell centre in maze units, heading in radians in [-pi, pi).
    """
    rng = np.random.default_rng([seed, 17])
    c = (int(rng.integers(maze.n)), int(rng.integers(maze.n)))
    return np.array([*maze.cell_centre(*c), float(rng.uniform(-np.pi, np.pi))])


# -- baselines -----------------------------------------------------------------------------------



def grid_poses(maze: Maze, k: int = GRID, seed: int = 0) -> np.ndarray:
    """``k * k`` free poses ``(x, y, heading)``: the points of a ``k x k`` grid over the maze, each moved
    to the centre of the maze cell it falls in (so none lies on a wall), with seeded headings.

    Parameters
    ----------
    maze : Maze
        The maze.
    k : int
        Poses per side (default :data:`GRID`).
    seed : int
        Seed of the headings (combined with the maze's seed).

    Returns
    -------
    numpy.ndarray, shape (k * k, 3)
        ``(x, y, heading)``: cell centres in maze units, headings in radians in [-pi, pi).

    Raises
    ------
    ValueError
        If two grid points fall in the same maze cell.
    """
    rng = np.random.default_rng([seed, maze.seed])
    pts = (np.arange(k) + 0.5) / k * maze.size
    out = []
    for x in pts:
        for y in pts:
            c = maze.cell_centre(*maze.cell_of([x, y]))
            out.append([c[0], c[1], float(rng.uniform(-np.pi, np.pi))])
    poses = np.array(out)
    if len({tuple(np.round(p[:2], 9)) for p in poses}) != len(poses):
        raise ValueError(f"grid_poses: a {k} x {k} grid does not give distinct cells in a {maze.n} x {maze.n} maze")
    return poses


def pose_pairs(n_poses: int, pairs: int | None = None, seed: int = 0) -> list[tuple[int, int]]:
    """All ordered pairs ``(i, j), i != j`` of ``n_poses`` poses, or a seeded subset of ``pairs`` of them.

    Parameters
    ----------
    n_poses : int
        Number of poses.
    pairs : int, optional
        Pairs wanted; None (or at least ``n_poses * (n_poses - 1)``) gives all of them.
    seed : int
        Seed of the subset.

    Returns
    -------
    list of (int, int)
        ``(start index, goal index)`` in lexicographic order.

    Raises
    ------
    ValueError
        If ``pairs < 1``.
    """
    every = [(i, j) for i in range(n_poses) for j in range(n_poses) if i != j]
    if pairs is None or pairs >= len(every):
        return every
    if pairs < 1:
        raise ValueError(f"pose_pairs: pairs must be >= 1, got {pairs}")
    idx = np.sort(np.random.default_rng(seed).choice(len(every), size=pairs, replace=False))
    return [every[i] for i in idx]


def execute(sim, start, controls) -> tuple[np.ndarray, int]:
    """Run ``controls`` open loop from ``start`` in ``sim``; returns executed poses and blocked moves.

    Parameters
    ----------
    sim : MazeSim
        The simulator (reset to ``start``).
    start : array_like, shape (3,)
        Start pose (x, y, heading).
    controls : array_like, shape (n, 2)
        Controls (turn rad, forward maze units).

    Returns
    -------
    poses : numpy.ndarray, shape (n + 1, 3)
        The start and the pose after each control.
    blocked : int
        Controls during which a wall stopped the robot.
    """
    poses = [sim.reset(start)]
    blocked = 0
    for u in np.asarray(controls, float).reshape(-1, 2):
        pose, hit = sim.step(u)
        poses.append(pose)
        blocked += int(hit)
    return np.array(poses), blocked


def outcome_row(pair, which, plan, executed, blocked, goal) -> dict:
    """One navigation outcome (Section V-B): a plan executed open loop from ``pair[0]``, judged at
    goal ``goal``; success is a found plan ending within :data:`SUCCESS_RADIUS` of it.

    Parameters
    ----------
    pair : tuple of int
        ``(start index, goal index)``.
    which : str
        The model the plan was made with (``"learned"``, ``"true"``, ...).
    plan : object
        The plan (:class:`cogmap.planning.hybrid_astar.Plan`: ``found``, ``length``, ``controls``,
        ``expansions``, ``queries``, ``seconds``, ``reason``).
    executed : numpy.ndarray
        ``(T, 3)`` poses the execution went through (:func:`execute`).
    blocked : int
        Moves a wall stopped.
    goal : numpy.ndarray
        ``(3,)`` the true goal pose.

    Returns
    -------
    dict
        ``start``, ``goal``, ``model``, ``found``, ``success``, ``final_error`` and lengths (maze
        units), ``heading_error`` (radians), ``blocked_moves`` and the planner's counts and time.
    """
    final = executed[-1]
    err = float(np.hypot(*(final[:2] - goal[:2])))
    walked = float(np.sum(np.hypot(*np.diff(executed[:, :2], axis=0).T))) if len(executed) > 1 else 0.0
    return {"start": pair[0], "goal": pair[1], "model": which, "found": plan.found,
            "success": bool(plan.found and err <= SUCCESS_RADIUS), "final_error": err,
            "heading_error": float(abs(wrap_angle(final[2] - goal[2]))),
            "plan_length": plan.length if plan.found else None, "executed_length": walked,
            "blocked_moves": blocked, "controls": len(plan.controls), "expansions": plan.expansions,
            "queries": plan.queries, "plan_s": plan.seconds, "reason": plan.reason}


def summarise(rows: list[dict]) -> dict:
    """Success rate per model, path length ratio of each learned model to the true simulator over pairs
    both found (``length_ratio`` for ``learned``, ``length_ratio_<name>`` for others), plan times.

    Parameters
    ----------
    rows : list of dict
        Rows of :func:`outcome_row` (those of :func:`cogmap.dvbf.navigate.navigate_pairs`).

    Returns
    -------
    dict
        Per model: ``pairs``, ``found``, ``success``, ``success_rate``, ``collided`` (plans with a
        blocked move), median and mean ``plan_s`` (seconds), median expansions; and for each model
        other than ``true`` the ``pairs``, ``mean``, ``median`` and ``max`` of its plan length over
        the true simulator's (None when no pair qualifies).
    """
    out = {}
    models = sorted({r["model"] for r in rows})
    for m in models:
        rs = [r for r in rows if r["model"] == m]
        t = np.array([r["plan_s"] for r in rs])
        out[m] = {"pairs": len(rs), "found": int(sum(r["found"] for r in rs)),
                  "success": int(sum(r["success"] for r in rs)),
                  "success_rate": float(np.mean([r["success"] for r in rs])) if rs else None,
                  "collided": int(sum(r["blocked_moves"] > 0 for r in rs)),
                  "plan_s_median": float(np.median(t)) if len(t) else None,
                  "plan_s_mean": float(np.mean(t)) if len(t) else None,
                  "expansions_median": float(np.median([r["expansions"] for r in rs])) if rs else None}
    by = {(r["start"], r["goal"], r["model"]): r for r in rows}
    for m in models:
        if m == "true" or "true" not in models:
            continue
        ratios = [by[(a, b, m)]["plan_length"] / by[(a, b, "true")]["plan_length"]
                  for (a, b, kind) in by if kind == "true" and by[(a, b, "true")]["found"]
                  and by.get((a, b, m), {}).get("found") and by[(a, b, "true")]["plan_length"] > 0]
        out["length_ratio" if m == "learned" else f"length_ratio_{m}"] = {
            "pairs": len(ratios), "mean": float(np.mean(ratios)) if ratios else None,
            "median": float(np.median(ratios)) if ratios else None, "max": float(np.max(ratios)) if ratios else None}
    return out

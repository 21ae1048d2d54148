"""Poses in a LiDAR maze: a seeded start, a grid of free poses and pairs of them, and open-loop
execution of a control sequence in the simulator (the DVBF-LM studies, paper Sections V and VI)."""

from __future__ import annotations

import numpy as np

from cogmap.envs.maze import Maze

GRID = 5  # 5 x 5 poses per maze


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

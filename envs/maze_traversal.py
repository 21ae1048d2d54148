"""Seeded maze traversals standing in for the paper's human operators (Section IV).

The operator repeatedly picks a distant cell, walks the shortest cell path to it and, per leg,
keeps a lateral offset from the corridor centre line: zero for room-crossing legs, close to a
wall for wall-following legs. A steering controller turns toward the next waypoint (at most
``max_turn`` per step) and moves ``step`` along the new heading, in the pybullet world, so walls
block it as they block the agent. Everything is recorded: true poses, commanded controls and
LiDAR scans.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np

from cogmap.genmodel.numerics import wrap_angle

from .maze import Maze
from .maze_sim import ActuationNoise, MazeSim


@dataclass(frozen=True)
class Traversal:
    """``poses (T, 3)`` true poses, ``controls (T - 1, 2)`` commanded ``(d_alpha, d_p)``
    moving pose t to t + 1, ``scans (T, n_beams)`` LiDAR at each pose, ``blocked (T - 1,)``."""

    poses: np.ndarray
    controls: np.ndarray
    scans: np.ndarray
    blocked: np.ndarray

    def __len__(self) -> int:
        return len(self.poses)


def cell_path(maze: Maze, start: tuple[int, int], goal: tuple[int, int]) -> list[tuple[int, int]]:
    """Shortest cell path (breadth-first search) from ``start`` to ``goal``, both included."""
    prev = {start: None}
    q = deque([start])
    while q:
        c = q.popleft()
        if c == goal:
            break
        for nb in maze.neighbours(*c):
            if nb not in prev:
                prev[nb] = c
                q.append(nb)
    if goal not in prev:
        raise ValueError(f"cell_path: {goal} is not reachable from {start}")
    out = [goal]
    while out[-1] != start:
        out.append(prev[out[-1]])
    return out[::-1]


def _waypoints(maze: Maze, path, offset: float) -> list[np.ndarray]:
    """Cell centres shifted sideways (to the left of the direction of travel) by ``offset``."""
    pts = []
    for k, c in enumerate(path):
        a = path[max(k - 1, 0)]
        b = path[min(k + 1, len(path) - 1)]
        d = np.array(b, float) - np.array(a, float)
        norm = np.hypot(*d)
        left = np.array([-d[1], d[0]]) / norm if norm > 0 else np.zeros(2)
        pts.append(maze.cell_centre(*c) + offset * maze.cell * left)
    return pts


def traverse(maze: Maze, steps: int, seed: int = 0, step: float = 0.01, max_turn: float = 0.35,
             noise: ActuationNoise | None = None, start=None, sim: MazeSim | None = None) -> Traversal:
    """Record ``steps`` poses of a seeded operator walking through ``maze``."""
    if steps < 1:
        raise ValueError(f"traverse: steps must be >= 1, got {steps}")
    rng = np.random.default_rng(seed)
    own = sim is None
    sim = sim or MazeSim(maze, noise=noise, seed=seed + 1)
    try:
        if start is None:
            c0 = (int(rng.integers(maze.n)), int(rng.integers(maze.n)))
            start = (*maze.cell_centre(*c0), float(rng.uniform(-np.pi, np.pi)))
        pose = sim.reset(start)
        poses, controls, scans, blocked = [pose], [], [sim.lidar()], []
        waypoints: list[np.ndarray] = []
        while len(poses) < steps:
            if not waypoints:
                here = maze.cell_of(pose[:2])
                cells = [(i, j) for i in range(maze.n) for j in range(maze.n) if (i, j) != here]
                far = np.array([abs(i - here[0]) + abs(j - here[1]) for i, j in cells], float)
                goal = cells[int(rng.choice(len(cells), p=far / far.sum()))]
                kind = rng.random()
                offset = 0.0 if kind < 0.4 else float(rng.choice([-1, 1]) * rng.uniform(0.2, 0.32))
                waypoints = _waypoints(maze, cell_path(maze, here, goal), offset)[1:]
            target = waypoints[0]
            d = target - pose[:2]
            dist = float(np.hypot(*d))
            if dist < 0.6 * step:
                waypoints.pop(0)
                continue
            err = float(wrap_angle(np.arctan2(d[1], d[0]) - pose[2]))
            turn = float(np.clip(err + 0.05 * rng.standard_normal(), -max_turn, max_turn))
            fwd = min(step, dist) if abs(err - turn) < 0.5 else 0.25 * step
            u = np.array([turn, fwd])
            pose, hit = sim.step(u)
            controls.append(u)
            blocked.append(hit)
            poses.append(pose)
            scans.append(sim.lidar())
            if hit:  # replan from where the wall stopped us
                waypoints = []
        return Traversal(np.array(poses), np.array(controls), np.array(scans), np.array(blocked, bool))
    finally:
        if own:
            sim.close()

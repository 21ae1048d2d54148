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

from cogmap.genmodel.contracts import Episode, EpisodePolicy
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


class MazeRun(Episode):
    """A maze run as :func:`cogmap.envs.episode.run` drives it: each control is stepped in the
    simulator and the true pose, control, scan and bump are recorded (no stopping rule of its own).

    Parameters
    ----------
    sim : MazeSim
        The simulator, already reset.
    pose : numpy.ndarray
        ``(3,)`` the start pose.
    scan : numpy.ndarray
        ``(n_beams,)`` the scan at the start.
    """

    def __init__(self, sim: MazeSim, pose, scan):
        self.sensors = sim
        self.poses, self.controls, self.scans, self.blocked = [pose], [], [scan], []

    def act(self, u):  # the outcome is (pose, scan, blocked)
        pose, hit = self.sensors.step(u)
        scan = self.sensors.lidar()
        self.poses.append(pose)
        self.controls.append(np.asarray(u, float))
        self.scans.append(scan)
        self.blocked.append(hit)
        return pose, scan, hit

    def traversal(self) -> Traversal:
        """The run so far as arrays."""
        return Traversal(np.array(self.poses), np.array(self.controls), np.array(self.scans),
                         np.array(self.blocked, bool))


class Operator(EpisodePolicy):
    """The seeded operator as a policy of :func:`cogmap.envs.episode.run`: walk the waypoints of a
    cell path to a distant cell, steering at most ``max_turn`` per step; a bump re-plans.

    Parameters
    ----------
    maze : Maze
        The maze.
    rng : numpy.random.Generator
        Draws the goals, the wall offsets and the steering noise.
    step : float
        Forward step per time step, maze units.
    max_turn : float
        Largest turn per time step, radians.
    """

    label = "operator"

    def __init__(self, maze: Maze, rng: np.random.Generator, step: float, max_turn: float):
        self.maze, self.rng, self.step_length, self.max_turn = maze, rng, step, max_turn
        self.waypoints: list[np.ndarray] = []

    def sense(self, sim, outcome):
        return outcome

    def step(self, sensed) -> np.ndarray:  # the next (turn, forward) from the last (pose, scan, blocked)
        maze, rng, step = self.maze, self.rng, self.step_length
        pose, _, hit = sensed
        if hit:  # replan from where the wall stopped us
            self.waypoints = []
        while True:
            if not self.waypoints:
                here = maze.cell_of(pose[:2])
                cells = [(i, j) for i in range(maze.n) for j in range(maze.n) if (i, j) != here]
                far = np.array([abs(i - here[0]) + abs(j - here[1]) for i, j in cells], float)
                goal = cells[int(rng.choice(len(cells), p=far / far.sum()))]
                kind = rng.random()
                offset = 0.0 if kind < 0.4 else float(rng.choice([-1, 1]) * rng.uniform(0.2, 0.32))
                self.waypoints = _waypoints(maze, cell_path(maze, here, goal), offset)[1:]
            d = self.waypoints[0] - pose[:2]
            dist = float(np.hypot(*d))
            if dist < 0.6 * step:
                self.waypoints.pop(0)
                continue
            err = float(wrap_angle(np.arctan2(d[1], d[0]) - pose[2]))
            turn = float(np.clip(err + 0.05 * rng.standard_normal(), -self.max_turn, self.max_turn))
            fwd = min(step, dist) if abs(err - turn) < 0.5 else 0.25 * step
            return np.array([turn, fwd])


def traverse(maze: Maze, steps: int, seed: int = 0, step: float = 0.01, max_turn: float = 0.35,
             noise: ActuationNoise | None = None, start=None, sim: MazeSim | None = None) -> Traversal:
    """Record ``steps`` poses of a seeded operator walking through ``maze``."""
    from .episode import run

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
        scan = sim.lidar()
        record = MazeRun(sim, pose, scan)
        run(record, Operator(maze, rng, step, max_turn), steps - 1, outcome=(pose, scan, False))
        return record.traversal()
    finally:
        if own:
            sim.close()

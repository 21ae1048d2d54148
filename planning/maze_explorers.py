"""Two exploration baselines for the LiDAR mazes (paper Section VI): a random walk and a
nearest-frontier explorer on an occupancy grid of the true returns."""

from __future__ import annotations

from collections import deque

import numpy as np

from cogmap.genmodel.numerics import wrap_angle


class RandomWalk:
    """The ``random`` baseline: a uniform turn in ``[-max_turn, max_turn]`` and a full step each time
    step; after a wall stopped it, a uniform turn in ``[-pi, pi]``.

    Parameters
    ----------
    cfg : ExploreConfig or any object with ``max_turn`` and ``max_step``
        ``max_turn`` (rad) and ``max_step`` (maze units).
    seed : int
        Seed of the walk.
    """

    def __init__(self, cfg, seed: int):
        self.cfg, self.rng, self.bounce = cfg, np.random.default_rng([seed, 1]), False

    def act(self, pose, scan, blocked: bool) -> np.ndarray:
        """The next control.

        Parameters
        ----------
        pose : numpy.ndarray, shape (3,)
            Current pose (unused).
        scan : numpy.ndarray, shape (n_beams,)
            Current scan (unused).
        blocked : bool
            Whether a wall stopped the last step.

        Returns
        -------
        numpy.ndarray, shape (2,)
            ``(turn in rad, forward = max_step)``.
        """
        if blocked:
            return np.array([self.rng.uniform(-np.pi, np.pi), self.cfg.max_step])
        return np.array([self.rng.uniform(-self.cfg.max_turn, self.cfg.max_turn), self.cfg.max_step])


class Frontier:
    """Nearest-frontier exploration on an occupancy grid from the true LiDAR returns at the true poses.

    Parameters
    ----------
    maze : Maze or any object with ``cell`` and ``size``
        The maze (:class:`cogmap.envs.maze.Maze`); the grid's cells are a quarter of its cell side.
    cfg : ExploreConfig or any object with ``max_turn``, ``max_step`` and ``replan_every``
        Control bounds (rad, maze units) and the re-plan period (steps).
    seed : int
        Seed of the random walk used when no frontier is left.
    lidar_range : float
        LiDAR range in maze units (a return at range is not a wall).

    Attributes
    ----------
    grid : numpy.ndarray of int8, shape (side, side)
        0 unknown, 1 free, 2 occupied; indexed by ``floor(xy / res)``.
    path : list of numpy.ndarray
        Remaining waypoints (cell centres) to the chosen frontier.
    """

    def __init__(self, maze, cfg, seed: int, lidar_range: float):
        self.cfg, self.maze = cfg, maze
        self.res = maze.cell / 4
        self.side = int(round(maze.size / self.res))
        self.grid = np.zeros((self.side, self.side), np.int8)  # 0 unknown, 1 free, 2 occupied
        self.range = lidar_range
        self.walk = RandomWalk(cfg, seed)
        self.path: list[np.ndarray] = []
        self.since = 0

    def _cell(self, xy):
        return np.clip(np.floor(np.asarray(xy) / self.res).astype(int), 0, self.side - 1)

    def update(self, pose, scan) -> None:
        """Mark the cells along each beam free (unless already occupied) and its end occupied.

        Parameters
        ----------
        pose : numpy.ndarray, shape (3,)
            True pose (x, y, heading); beam ``k`` points at ``heading + 2 pi k / n_beams``.
        scan : numpy.ndarray, shape (n_beams,)
            True ranges in maze units.
        """
        n = len(scan)
        ang = pose[2] + 2 * np.pi * np.arange(n) / n
        d = np.stack([np.cos(ang), np.sin(ang)], 1)
        for r, v in zip(scan, d, strict=True):
            s = np.arange(0.0, max(r - self.res, 0.0), self.res / 2)
            ij = self._cell(pose[:2] + s[:, None] * v)
            free = self.grid[ij[:, 0], ij[:, 1]] != 2
            self.grid[ij[free, 0], ij[free, 1]] = 1
            if r < 0.999 * self.range:
                i, j = self._cell(pose[:2] + r * v)
                self.grid[i, j] = 2

    def _plan(self, pose) -> list[np.ndarray]:
        start = tuple(self._cell(pose[:2]))
        prev = {start: None}
        q = deque([start])
        g = self.grid
        while q:
            c = q.popleft()
            i, j = c
            if c != start and any(0 <= a < self.side and 0 <= b < self.side and g[a, b] == 0
                                  for a, b in ((i + 1, j), (i - 1, j), (i, j + 1), (i, j - 1))):
                path = [c]
                while prev[path[-1]] is not None:
                    path.append(prev[path[-1]])
                return [(np.array(p, float) + 0.5) * self.res for p in path[::-1][1:]]
            for nb in ((i + 1, j), (i - 1, j), (i, j + 1), (i, j - 1)):
                if 0 <= nb[0] < self.side and 0 <= nb[1] < self.side and nb not in prev and g[nb] == 1:
                    prev[nb] = c
                    q.append(nb)
        return []

    def act(self, pose, scan, blocked: bool) -> np.ndarray:
        """Update the grid and steer along the shortest 4-connected path to the nearest frontier.

        Re-plans when blocked, when the path is used up or every ``replan_every`` steps; turns
        towards the next waypoint (at most ``max_turn``) and moves only if the remaining heading
        error is below 0.5 rad; with no frontier left, acts as :class:`RandomWalk`.

        Parameters
        ----------
        pose : numpy.ndarray, shape (3,)
            True pose (x, y, heading).
        scan : numpy.ndarray, shape (n_beams,)
            True ranges.
        blocked : bool
            Whether a wall stopped the last step.

        Returns
        -------
        numpy.ndarray, shape (2,)
            ``(turn in rad, forward in maze units)``.
        """
        self.update(pose, scan)
        if blocked:  # the bump says a wall is right ahead: mark it, so the re-plan goes around it
            i, j = self._cell(pose[:2] + 0.75 * self.res * np.array([np.cos(pose[2]), np.sin(pose[2])]))
            if (i, j) != tuple(self._cell(pose[:2])):
                self.grid[i, j] = 2
        self.since += 1
        if blocked or not self.path or self.since >= self.cfg.replan_every:
            self.path = self._plan(pose)
            self.since = 0
        while self.path and np.hypot(*(self.path[0] - pose[:2])) < 0.6 * self.cfg.max_step:
            self.path.pop(0)
        if not self.path:
            return self.walk.act(pose, scan, blocked)
        d = self.path[0] - pose[:2]
        err = float(wrap_angle(np.arctan2(d[1], d[0]) - pose[2]))
        turn = float(np.clip(err, -self.cfg.max_turn, self.cfg.max_turn))
        fwd = min(self.cfg.max_step, float(np.hypot(*d))) if abs(err - turn) < 0.5 else 0.0
        return np.array([turn, fwd])


# -- the DVBF-LM agent ---------------------------------------------------------------------------

"""A fast numpy grid world: rooms joined by one-cell doors, a colour per free cell.

Poses are (col, row, heading) with heading in {0, 1, 2, 3} = east, north, west, south.
Actions 0..3 move one cell toward that heading (and face it); action 4 stays. A move into
a wall fails and leaves the agent in place. The exact model is exposed for building
generative models: `cells`, `colors`, `next_cell`, `B()` and `A()`.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from .robot import MoveResult
from .sensors import FaultSchedule

MOVES = np.array([[1, 0], [0, 1], [-1, 0], [0, -1]])
STAY = 4


def rooms_map(n_x: int = 2, n_y: int = 2, room: int = 4) -> np.ndarray:
    """Boolean wall map (rows = y) of n_x by n_y square rooms, doors in every shared wall."""
    w, h = n_x * (room + 1) + 1, n_y * (room + 1) + 1
    wall = np.zeros((h, w), bool)
    wall[:: room + 1, :] = True
    wall[:, :: room + 1] = True
    mid = room // 2 + 1
    for i in range(n_x):
        for j in range(1, n_y):  # doors in horizontal walls
            wall[j * (room + 1), i * (room + 1) + mid] = False
    for i in range(1, n_x):
        for j in range(n_y):
            wall[j * (room + 1) + mid, i * (room + 1)] = False
    return wall


class GridWorld:
    """Rich API mirroring `NavSim` on a discrete grid (no physics client)."""

    n_actions = 5

    def __init__(self, walls: np.ndarray | None = None, n_colors: int = 6, seed: int = 0):
        self.walls = rooms_map() if walls is None else np.asarray(walls, bool)
        free = np.argwhere(~self.walls)  # (row, col)
        self.cells = free[:, ::-1].copy()  # (x, y)
        self.index = -np.ones(self.walls.shape, int)
        self.index[free[:, 0], free[:, 1]] = np.arange(len(free))
        self.n_colors = int(n_colors)
        self.colors = np.random.default_rng(seed).integers(n_colors, size=len(free))
        self._next = np.array([[self._step_cell(c, a) for a in range(self.n_actions)]
                               for c in range(self.n_cells)])
        self.faults = FaultSchedule()
        self.reset(seed)

    @property
    def n_cells(self) -> int:
        return len(self.cells)

    def _step_cell(self, cell: int, action: int) -> int:
        if action == STAY:
            return cell
        x, y = self.cells[cell] + MOVES[action]
        if 0 <= y < self.walls.shape[0] and 0 <= x < self.walls.shape[1] and not self.walls[y, x]:
            return int(self.index[y, x])
        return cell

    def next_cell(self, cell: int, action: int) -> int:
        return int(self._next[cell, action])

    def B(self) -> np.ndarray:
        """Transition tensor B[next, current, action] (one-hot columns)."""
        B = np.zeros((self.n_cells, self.n_cells, self.n_actions))
        cur = np.arange(self.n_cells)
        for a in range(self.n_actions):
            B[self._next[:, a], cur, a] = 1.0
        return B

    def A(self) -> np.ndarray:
        """Observation matrix A[colour, cell] (one-hot columns)."""
        A = np.zeros((self.n_colors, self.n_cells))
        A[self.colors, np.arange(self.n_cells)] = 1.0
        return A

    def cell_of(self, xy) -> int:
        return int(self.index[int(xy[1]), int(xy[0])])

    # ------------------------------------------------------------- episode API
    def reset(self, seed=None, start=None) -> np.ndarray:
        self.rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
        cell = int(self.rng.integers(self.n_cells)) if start is None else int(start)
        self.cell, self.heading = cell, 0
        self.odom = np.array([*self.cells[cell], 0], int)
        self.step_count = 0
        self.faults.clear()
        return self.true_pose()

    def true_pose(self) -> np.ndarray:
        return np.array([*self.cells[self.cell], self.heading], int)

    def odometry(self) -> np.ndarray | None:
        if self.faults.dropped("odometry", self.step_count):
            return None
        return self.odom.copy()

    def step_action(self, action: int) -> MoveResult:
        if not 0 <= int(action) < self.n_actions:
            raise ValueError(f"action must be in [0, {self.n_actions - 1}]")
        start = self.true_pose()
        nxt = self.next_cell(self.cell, int(action))
        ok = action == STAY or nxt != self.cell
        if action != STAY:
            self.heading = int(action)
            self.odom[2] = int(action)
            if ok:
                self.odom[:2] += MOVES[int(action)]
        self.cell = nxt
        self.step_count += 1
        dist = 0.0 if action == STAY or not ok else 1.0
        return MoveResult(bool(ok), dist, 0.0 if action == STAY else 1.0, start,
                          self.true_pose())

    def observe(self) -> int | None:
        """Colour index of the current cell, or None while the camera is dropped."""
        if self.faults.dropped("camera", self.step_count):
            return None
        return int(self.colors[self.cell])

    def obstacle_signal(self) -> np.ndarray | None:
        """1 where heading k is blocked by a wall; None while the LiDAR is dropped."""
        if self.faults.dropped("lidar", self.step_count):
            return None
        return (self._next[self.cell, :4] == self.cell).astype(np.int8)

    def teleport(self, cell: int) -> None:
        self.cell = int(cell)

    def inject_fault(self, stream: str, start_step: int, length: int) -> None:
        self.faults.add(stream, start_step, length)


class GridWorldEnv(gym.Env):
    """Gymnasium view of `GridWorld`. Dropped colour = `n_colors`; see `valid`."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 4}

    def __init__(self, n_x: int = 2, n_y: int = 2, room: int = 4, n_colors: int = 6,
                 world_seed: int = 0, faults=(), render_mode: str | None = None):
        self.world = GridWorld(rooms_map(n_x, n_y, room), n_colors, world_seed)
        self.base_faults = [tuple(f) for f in faults]
        self.render_mode = render_mode
        self.observation_space = spaces.Dict({
            "color": spaces.Discrete(n_colors + 1),
            "odometry": spaces.Box(-10_000, 10_000, (3,), np.int64),
            "obstacle": spaces.MultiBinary(4),
            "valid": spaces.MultiBinary(3),
        })
        self.action_space = spaces.Discrete(GridWorld.n_actions)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        options = options or {}
        self.world.reset(self.np_random, options.get("start"))
        for f in list(self.base_faults) + list(options.get("faults", ())):
            self.world.inject_fault(*f)
        return self._obs(), {"true_pose": self.world.true_pose()}

    def step(self, action):
        res = self.world.step_action(int(action))
        info = {"true_pose": self.world.true_pose(), "success": res.success}
        return self._obs(), 0.0, False, False, info

    def _obs(self):
        w = self.world
        col, odom, obs = w.observe(), w.odometry(), w.obstacle_signal()
        return {
            "color": np.int64(w.n_colors if col is None else col),
            "odometry": np.zeros(3, np.int64) if odom is None else odom.astype(np.int64),
            "obstacle": np.zeros(4, np.int8) if obs is None else obs,
            "valid": np.array([obs is not None, col is not None, odom is not None], np.int8),
        }

    def render(self):
        if self.render_mode != "rgb_array":
            return None
        img = np.where(self.world.walls[..., None], 30, 230).astype(np.uint8).repeat(3, 2)
        x, y = self.world.cells[self.world.cell]
        img[y, x] = (220, 0, 0)
        return np.ascontiguousarray(img[::-1].repeat(8, 0).repeat(8, 1))

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
from .sensors import FaultInjection, FaultSchedule

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


class GridWorld(FaultInjection):
    """Rich API mirroring :class:`NavSim` on a discrete grid (no physics client).

    Poses are ``(col, row, heading)`` ints, heading 0..3 = east, north, west, south; actions 0..3
    move one cell toward that heading, action 4 stays. Free cells are numbered in row-major order
    of the wall map; ``cells`` holds their ``(x, y)`` and ``colors`` their colour.

    Parameters
    ----------
    walls : numpy.ndarray, optional
        ``(rows, cols)`` bool wall map (rows = y); default :func:`rooms_map` (2 x 2 rooms of 4 cells).
    n_colors : int, optional
        Number of colours drawn uniformly per free cell, default 6.
    seed : int, optional
        Seed of the colours and of the first start draw, default 0.
    """

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
        """Number of free cells (states)."""
        return len(self.cells)

    def _step_cell(self, cell: int, action: int) -> int:
        if action == STAY:
            return cell
        x, y = self.cells[cell] + MOVES[action]
        if 0 <= y < self.walls.shape[0] and 0 <= x < self.walls.shape[1] and not self.walls[y, x]:
            return int(self.index[y, x])
        return cell

    def next_cell(self, cell: int, action: int) -> int:
        """Cell reached from ``cell`` under ``action`` (the same cell when a wall blocks it or for stay).

        Parameters
        ----------
        cell : int
            Free-cell index.
        action : int
            Action 0..4.

        Returns
        -------
        int
            Free-cell index.
        """
        return int(self._next[cell, action])

    def B(self) -> np.ndarray:
        """Exact transition tensor ``B[next, current, action]`` (one-hot columns).

        Returns
        -------
        numpy.ndarray
            ``(n_cells, n_cells, 5)`` float.
        """
        B = np.zeros((self.n_cells, self.n_cells, self.n_actions))
        cur = np.arange(self.n_cells)
        for a in range(self.n_actions):
            B[self._next[:, a], cur, a] = 1.0
        return B

    def A(self) -> np.ndarray:
        """Exact observation matrix ``A[colour, cell]`` (one-hot columns).

        Returns
        -------
        numpy.ndarray
            ``(n_colors, n_cells)`` float.
        """
        A = np.zeros((self.n_colors, self.n_cells))
        A[self.colors, np.arange(self.n_cells)] = 1.0
        return A

    def cell_of(self, xy) -> int:
        """Free-cell index at grid position ``xy`` (-1 on a wall).

        Parameters
        ----------
        xy : sequence
            ``(x, y)`` = (column, row).

        Returns
        -------
        int
        """
        return int(self.index[int(xy[1]), int(xy[0])])

    # ------------------------------------------------------------- episode API
    def reset(self, seed=None, start=None) -> np.ndarray:
        """Start an episode: place the agent facing east, zero the odometry offset, clear faults.

        Parameters
        ----------
        seed : int or numpy.random.Generator or None, optional
            Seed (or generator) of the start draw.
        start : int, optional
            Start cell index; default drawn uniformly.

        Returns
        -------
        numpy.ndarray
            ``(3,)`` int true pose ``(col, row, heading)``.
        """
        self.rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
        cell = int(self.rng.integers(self.n_cells)) if start is None else int(start)
        self.cell, self.heading = cell, 0
        self.odom = np.array([*self.cells[cell], 0], int)
        self.step_count = 0
        self.faults.clear()
        return self.true_pose()

    def true_pose(self) -> np.ndarray:
        """True pose ``(col, row, heading)``.

        Returns
        -------
        numpy.ndarray
            ``(3,)`` int.
        """
        return np.array([*self.cells[self.cell], self.heading], int)

    def odometry(self) -> np.ndarray | None:
        """Odometry pose ``(col, row, heading)`` (exact increments), or None while the stream is dropped.

        Returns
        -------
        numpy.ndarray or None
            ``(3,)`` int.
        """
        if self.faults.dropped("odometry", self.step_count):
            return None
        return self.odom.copy()

    def step_action(self, action: int) -> MoveResult:
        """Apply an action for one step; a move into a wall fails and leaves the agent in place.

        Parameters
        ----------
        action : int
            0..3 move east/north/west/south (and face it), 4 stays.

        Returns
        -------
        MoveResult
            ``distance`` and ``requested`` in cells (1 or 0), poses as ``(col, row, heading)``.

        Raises
        ------
        ValueError
            If ``action`` is out of range.
        """
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
        """Colour index of the current cell, or None while the camera is dropped.

        Returns
        -------
        int or None
        """
        if self.faults.dropped("camera", self.step_count):
            return None
        return int(self.colors[self.cell])

    def obstacle_signal(self) -> np.ndarray | None:
        """Per heading 0..3, 1 where a wall blocks the move; None while the LiDAR is dropped.

        Returns
        -------
        numpy.ndarray or None
            ``(4,)`` int8.
        """
        if self.faults.dropped("lidar", self.step_count):
            return None
        return (self._next[self.cell, :4] == self.cell).astype(np.int8)

    def teleport(self, cell: int) -> None:
        """Kidnap the agent to another cell (odometry does not notice).

        Parameters
        ----------
        cell : int
            Free-cell index.
        """
        self.cell = int(cell)


class GridWorldEnv(gym.Env):
    """Gymnasium view of :class:`GridWorld`.

    Observations are dicts: ``"color"`` (``n_colors`` when the camera is dropped), ``"odometry"``
    ``(3,)`` int64, ``"obstacle"`` ``(4,)`` int8 and ``"valid"`` ``(3,)`` int8 flags for
    (obstacle, colour, odometry) being present. Reward is always 0 and episodes never end.

    Parameters
    ----------
    n_x, n_y : int, optional
        Rooms along x and y, default 2 x 2.
    room : int, optional
        Room side in cells, default 4.
    n_colors : int, optional
        Number of colours, default 6.
    world_seed : int, optional
        Seed of the colours, default 0.
    faults : sequence of tuple, optional
        ``(stream, start_step, length)`` dropouts applied on every reset.
    render_mode : str, optional
        ``"rgb_array"`` or None.
    """

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
        """Reset the episode (Gymnasium API).

        Parameters
        ----------
        seed : int, optional
            Seed of the environment's generator.
        options : dict, optional
            ``"start"``: start cell index; ``"faults"``: extra ``(stream, start_step, length)`` dropouts.

        Returns
        -------
        observation : dict
            As described in the class docstring.
        info : dict
            ``{"true_pose": (3,) int}``.
        """
        super().reset(seed=seed)
        options = options or {}
        self.world.reset(self.np_random, options.get("start"))
        for f in list(self.base_faults) + list(options.get("faults", ())):
            self.world.inject_fault(*f)
        return self._obs(), {"true_pose": self.world.true_pose()}

    def step(self, action):
        """Take one action (Gymnasium API).

        Parameters
        ----------
        action : int
            0..4 (see :class:`GridWorld`).

        Returns
        -------
        observation : dict
        reward : float
            Always 0.
        terminated, truncated : bool
            Always False.
        info : dict
            ``"true_pose"`` and ``"success"`` (False when a wall blocked the move).
        """
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
        """Image of the map with the agent in red (``render_mode="rgb_array"`` only).

        Returns
        -------
        numpy.ndarray or None
            ``(8 * rows, 8 * cols, 3)`` uint8, north up; None in other render modes.
        """
        if self.render_mode != "rgb_array":
            return None
        img = np.where(self.world.walls[..., None], 30, 230).astype(np.uint8).repeat(3, 2)
        x, y = self.world.cells[self.world.cell]
        img[y, x] = (220, 0, 0)
        return np.ascontiguousarray(img[::-1].repeat(8, 0).repeat(8, 1))

"""Gymnasium wrapper around :class:`~cogmap.envs.maze_sim.MazeSim` (id ``cogmap/LidarMaze-v0``).

Observation: ``Box(0, 0.53, (20,))`` LiDAR ranges, beam 0 along the heading.
Action: ``Box([-max_turn, 0], [max_turn, max_step])``: rotate by ``action[0]`` then move
``action[1]`` along the new heading (Appendix A-A). Reward 0; episodes never terminate (the
registered step limit truncates them). ``info`` holds the true pose and whether a wall blocked the
move. ``reset(seed=s)`` draws the start cell; the maze itself is fixed by the constructor's
``maze_seed`` (or ``options={"maze_seed": k}`` at reset).
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from .maze import make_maze
from .maze_sim import LIDAR_RANGE, N_BEAMS, ActuationNoise, MazeSim


class LidarMazeEnv(gym.Env):
    metadata = {"render_modes": ["rgb_array"], "render_fps": 20}

    def __init__(self, maze_seed: int = 0, complexity: str = "moderate", corridor: str = "medium",
                 max_turn: float = 0.5, max_step: float = 0.03, noise: ActuationNoise | dict | None = None,
                 render_mode: str | None = None):
        self.maze_args = (complexity, corridor)
        self.noise = noise if isinstance(noise, ActuationNoise) or noise is None else ActuationNoise(**noise)
        self.maze = make_maze(maze_seed, complexity, corridor)
        self.sim = MazeSim(self.maze, self.noise)
        self.render_mode = render_mode
        self.observation_space = spaces.Box(0.0, LIDAR_RANGE, (N_BEAMS,), np.float32)
        self.action_space = spaces.Box(np.array([-max_turn, 0.0], np.float32),
                                       np.array([max_turn, max_step], np.float32), dtype=np.float32)
        self.path: list[np.ndarray] = []

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        options = options or {}
        if "maze_seed" in options and int(options["maze_seed"]) != self.maze.seed:
            self.sim.close()
            self.maze = make_maze(int(options["maze_seed"]), *self.maze_args)
            self.sim = MazeSim(self.maze, self.noise)
        self.sim.rng = np.random.default_rng(self.np_random.integers(2**32))
        start = options.get("start")
        if start is None:
            i, j = self.np_random.integers(self.maze.n, size=2)
            start = (*self.maze.cell_centre(int(i), int(j)), float(self.np_random.uniform(-np.pi, np.pi)))
        pose = self.sim.reset(start)
        self.path = [pose]
        return self._obs(), {"true_pose": pose, "blocked": False}

    def step(self, action):
        a = np.clip(np.asarray(action, float), self.action_space.low, self.action_space.high)
        pose, blocked = self.sim.step(a)
        self.path.append(pose)
        return self._obs(), 0.0, False, False, {"true_pose": pose, "blocked": bool(blocked)}

    def _obs(self):
        return self.sim.lidar().astype(np.float32)

    def render(self):
        if self.render_mode != "rgb_array":
            return None
        from .maze_render import maze_image

        return maze_image(self.maze, self.sim.pose, np.array(self.path))

    def close(self):
        self.sim.close()

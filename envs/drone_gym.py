"""Gymnasium wrapper around :class:`~cogmap.envs.drone_sim.DroneSim` (id ``cogmap/DroneField-v0``).

Observation (Dict):
  position  float32 (3,) drone position (m, z up)
  target    float32 (3,) target position (m)
  lidar     float32 (n_rays,) LiDAR ranges (m) to obstacles, ``lidar_range`` where nothing (or only
            the ground) was hit; rays are 16 channels over +-10 deg x 25 azimuths (channel-major)
Action: Box(-1, 1, (3,)): a displacement of ``max_step`` (5 m) times the action, flown as one
straight segment at 2 m/s (1.5 m/s within 5 m of the target).
Reward: the reduction of the distance to the target, minus 1 per collision.
``terminated``: the target is within 1.5 m, or a collision with ``end_on_collision=True``.
Episodes are truncated by the registered limit of 250 steps. ``reset(seed=...)`` draws the
target (the field is fixed by ``field_seed``).
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from .drone_sim import DroneConfig, DroneSim

SUCCESS_RADIUS = 1.5
COORD_LIMIT = 1e3


class DroneFieldEnv(gym.Env):
    metadata = {"render_modes": ["rgb_array"], "render_fps": 4}

    def __init__(self, field_seed: int = 0, end_on_collision: bool = False, max_step: float = 5.0,
                 render_mode: str | None = None):
        self.config = DroneConfig(end_on_collision=end_on_collision)
        self.sim = DroneSim(field_seed, self.config)
        self.max_step = float(max_step)
        self.render_mode = render_mode
        n = self.config.n_rays
        self.observation_space = spaces.Dict({
            "position": spaces.Box(-COORD_LIMIT, COORD_LIMIT, (3,), np.float32),
            "target": spaces.Box(-COORD_LIMIT, COORD_LIMIT, (3,), np.float32),
            "lidar": spaces.Box(0.0, self.config.lidar_range, (n,), np.float32),
        })
        self.action_space = spaces.Box(-1.0, 1.0, (3,), np.float32)
        self.target = np.zeros(3)

    def _obs(self):
        scan = self.sim.scan()
        r = np.minimum(scan.ranges, self.config.lidar_range)
        return {"position": self.sim.position.astype(np.float32), "target": self.target.astype(np.float32),
                "lidar": r.astype(np.float32)}

    def _distance(self) -> float:
        return float(np.linalg.norm(self.target - self.sim.position))

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        self.sim.reset()
        self.target = self.sim.sample_target(self.np_random)
        return self._obs(), {"distance": self._distance(), "collisions": 0}

    def step(self, action):
        a = np.clip(np.asarray(action, float), -1.0, 1.0) * self.max_step
        d0 = self._distance()
        before = self.sim.collisions
        wp = self.sim.position + a
        wp[2] = max(wp[2], self.config.radius + 0.3)
        speed = self.config.slow_speed if d0 < 5.0 else self.config.speed
        self.sim.fly_to(wp, speed)
        d1 = self._distance()
        hits = self.sim.collisions - before
        terminated = bool(d1 <= SUCCESS_RADIUS or self.sim.crashed)
        info = {"distance": d1, "collisions": self.sim.collisions, "crashed": self.sim.crashed,
                "time": self.sim.time}
        return self._obs(), float(d0 - d1 - hits), terminated, False, info

    def render(self):
        if self.render_mode != "rgb_array":
            return None
        from .drone_render import topdown_image

        return topdown_image(self.sim.field, np.array(self.sim.path), self.target)

    def close(self):
        self.sim.close()

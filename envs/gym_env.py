"""Gymnasium wrapper around `NavSim`.

Observation (Dict):
  lidar     float32 (n_beams,) ranges in m, robot frame, beam 0 forward
  panorama  uint8 (h, w * n_views, 3), aligned to the odometry frame
  odometry  float32 (3,) odometry pose (x, y, yaw)
  obstacle  int8 (n_directions,) 1 = blocked toward odometry heading k * 360 / n
  valid     int8 (3,) 1 if (lidar, camera, odometry) delivered data this step
A dropped stream is zero-filled in the observation (so it stays inside the declared
space) and flagged 0 in `valid` and in `info["valid"]`; the obstacle signal is zero-filled
whenever the LiDAR is dropped. Always check `valid` before using a stream.
Actions: Discrete(n_directions + 1): k < n_directions drives `step_length` toward
odometry heading k * 360 / n_directions; the last action stays. Reward is always 0
(exploration and goal metrics are computed by the caller); episodes never terminate
and are truncated by the registered step limit.
"""

from __future__ import annotations

import dataclasses

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from .layouts import Layout, make_layout
from .robot import OdometryNoise
from .sim import NavSim, SimConfig

ODOM_LIMIT = 1e4


class NavEnv(gym.Env):
    """A pybullet layout with the robot, as a Gymnasium environment."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 4}

    def __init__(self, layout: str | Layout = "mini_warehouse", layout_seed: int = 0,
                 config: SimConfig | None = None, noise: OdometryNoise | dict | None = None,
                 faults=(), render_mode: str | None = None, layout_kwargs: dict | None = None, **config_overrides):
        cfg = config or SimConfig()
        if noise is not None:
            cfg = dataclasses.replace(
                cfg, noise=noise if isinstance(noise, OdometryNoise) else OdometryNoise(**noise))
        if config_overrides:
            cfg = dataclasses.replace(cfg, **config_overrides)
        self.config = cfg
        # layout_kwargs: extra arguments of the layout builder, e.g. {"kind": "T"} for "building"
        lay = make_layout(layout, layout_seed, **(layout_kwargs or {})) if isinstance(layout, str) else layout
        self.sim = NavSim(lay, cfg, seed=0)
        self.base_faults = [tuple(f) for f in faults]
        self.render_mode = render_mode
        h, w = cfg.image_size
        self.observation_space = spaces.Dict({
            "lidar": spaces.Box(0.0, cfg.lidar_range, (cfg.lidar_beams,), np.float32),
            "panorama": spaces.Box(0, 255, (h, w * cfg.n_views, 3), np.uint8),
            "odometry": spaces.Box(-ODOM_LIMIT, ODOM_LIMIT, (3,), np.float32),
            "obstacle": spaces.MultiBinary(cfg.n_directions),
            "valid": spaces.MultiBinary(3),
        })
        self.action_space = spaces.Discrete(cfg.n_directions + 1)

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        options = options or {}
        self.sim.reset(self.np_random, start=options.get("start"))
        for f in list(self.base_faults) + list(options.get("faults", ())):
            self.sim.inject_fault(*f)
        return self._obs(), self._info(None)

    def step(self, action):
        res = self.sim.step_action(int(action))
        return self._obs(), 0.0, False, False, self._info(res)

    def _obs(self):
        c = self.config
        h, w = c.image_size
        lidar, pano, odom = self.sim.lidar(), self.sim.panorama(), self.sim.odometry()
        obst = self.sim.obstacle_signal()
        self._valid = np.array([lidar is not None, pano is not None, odom is not None], np.int8)
        return {
            "lidar": (np.zeros(c.lidar_beams) if lidar is None else lidar).astype(np.float32),
            "panorama": np.zeros((h, w * c.n_views, 3), np.uint8) if pano is None else pano,
            "odometry": np.clip(np.zeros(3) if odom is None else odom,
                                -ODOM_LIMIT, ODOM_LIMIT).astype(np.float32),
            "obstacle": (np.zeros(c.n_directions) if obst is None else obst).astype(np.int8),
            "valid": self._valid.copy(),
        }

    def _info(self, res):
        info = {
            "true_pose": self.sim.true_pose(),
            "step": self.sim.step_count,
            "valid": dict(zip(("lidar", "camera", "odometry"), map(bool, self._valid),
                              strict=True)),
        }
        if res is not None:
            info.update(success=res.success, distance=res.distance, blocked_by=res.blocked_by)
        return info

    def render(self):
        if self.render_mode != "rgb_array":
            return None
        from .render import grid_image

        return grid_image(self.sim.grid, self.sim.true_pose(), np.array(self.sim.path))

    def close(self):
        self.sim.close()

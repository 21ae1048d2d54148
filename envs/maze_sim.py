"""pybullet world for a :class:`~cogmap.envs.maze.Maze` with a point agent and a 20-beam LiDAR.

Paper Appendix A-A: the agent is a point (radius 1e-5) that rotates freely and moves only along
its heading; a control ``u = (d_alpha, d_p)`` first rotates, then translates; walls block the
translation. The range finder has 20 beams over the full circle (beam 0 along the heading),
each of length 0.53; that length is returned when a beam hits nothing. Walls are zero-mass
pybullet boxes, queried by ray tests only (DIRECT mode, no dynamics stepping).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cogmap.genmodel.numerics import wrap_angle

from .maze import Maze

N_BEAMS = 20
LIDAR_RANGE = 0.53
AGENT_RADIUS = 1e-5
WALL_HEIGHT = 0.1
RAY_Z = 0.05


@dataclass(frozen=True)
class ActuationNoise:
    """Execution noise of a control: the simulator applies ``d_alpha + N(0, rot_std^2)`` and
    ``d_p * (1 + N(0, trans_frac^2))``; the agent only knows the commanded control."""

    rot_std: float = 0.0
    trans_frac: float = 0.0


#: the robot's actuation noise in every DVBF-LM run and study (heading std per step, translation fraction)
ROBOT_NOISE = ActuationNoise(rot_std=0.005, trans_frac=0.05)


class MazeSim:
    """A maze in its own pybullet client, one point agent, LiDAR by ``rayTestBatch``."""

    def __init__(self, maze: Maze, noise: ActuationNoise | None = None, seed: int = 0,
                 n_beams: int = N_BEAMS, lidar_range: float = LIDAR_RANGE):
        import pybullet as p

        self._p = p
        self.maze = maze
        self.noise = noise or ActuationNoise()
        self.rng = np.random.default_rng(seed)
        self.n_beams = int(n_beams)
        self.lidar_range = float(lidar_range)
        self.beam_angles = 2 * np.pi * np.arange(self.n_beams) / self.n_beams
        self.client = p.connect(p.DIRECT)
        self.wall_ids = []
        for cx, cy, sx, sy in maze.walls:
            col = p.createCollisionShape(p.GEOM_BOX, halfExtents=[sx / 2, sy / 2, WALL_HEIGHT / 2],
                                         physicsClientId=self.client)
            self.wall_ids.append(p.createMultiBody(0, col, -1, [cx, cy, WALL_HEIGHT / 2],
                                                   physicsClientId=self.client))
        self.pose = np.array([*maze.cell_centre(0, 0), 0.0])
        # stop this far in front of a wall (the agent's radius, plus a numerical margin)
        self.margin = AGENT_RADIUS + 1e-4 * maze.size

    # -- geometry ----------------------------------------------------------------------------
    def _cast(self, origin, angles, length):
        p = self._p
        c, s = np.cos(angles), np.sin(angles)
        frm = np.stack([np.full_like(c, origin[0]), np.full_like(c, origin[1]), np.full_like(c, RAY_Z)], 1)
        to = np.stack([origin[0] + length * c, origin[1] + length * s, np.full_like(c, RAY_Z)], 1)
        out = p.rayTestBatch(frm.tolist(), to.tolist(), physicsClientId=self.client)
        hit = np.array([o[0] >= 0 for o in out])
        frac = np.array([o[2] for o in out])
        return hit, frac * np.asarray(length, float)

    def lidar(self, pose=None) -> np.ndarray:
        """Ranges (n_beams,) at ``pose`` (default: the agent's), beam k at heading + 2 pi k / n."""
        pose = self.pose if pose is None else np.asarray(pose, float)
        hit, dist = self._cast(pose[:2], pose[2] + self.beam_angles, self.lidar_range)
        return np.where(hit, dist, self.lidar_range)

    def lidar_batch(self, poses, chunk: int = 8000) -> np.ndarray:
        """Ranges ``(K, n_beams)`` at poses ``(K, 3)``, cast in batches of at most ``chunk`` rays."""
        poses = np.asarray(poses, float).reshape(-1, 3)
        origins = np.repeat(poses[:, :2], self.n_beams, axis=0)
        angles = (poses[:, 2:3] + self.beam_angles).ravel()
        out = np.empty(len(angles))
        for a in range(0, len(angles), chunk):
            hit, dist = self._cast_many(origins[a:a + chunk], angles[a:a + chunk], self.lidar_range)
            out[a:a + chunk] = np.where(hit, dist, self.lidar_range)
        return out.reshape(len(poses), self.n_beams)

    def _cast_many(self, origins, angles, length):
        p = self._p
        c, s = np.cos(angles), np.sin(angles)
        z = np.full_like(c, RAY_Z)
        frm = np.stack([origins[:, 0], origins[:, 1], z], 1)
        to = np.stack([origins[:, 0] + length * c, origins[:, 1] + length * s, z], 1)
        out = p.rayTestBatch(frm.tolist(), to.tolist(), physicsClientId=self.client)
        return np.array([o[0] >= 0 for o in out]), np.array([o[2] for o in out]) * float(length)

    def free_distance(self, xy, heading: float, length: float) -> float:
        """How far the point can move from ``xy`` along ``heading`` (at most ``length``)."""
        if length <= 0:
            return 0.0
        hit, dist = self._cast(np.asarray(xy, float), np.array([heading]), length + self.margin)
        return float(min(length, max(0.0, dist[0] - self.margin))) if hit[0] else float(length)

    # -- dynamics ----------------------------------------------------------------------------
    def reset(self, pose) -> np.ndarray:
        pose = np.asarray(pose, float)
        if pose.shape != (3,) or not np.all(np.isfinite(pose)):
            raise ValueError(f"MazeSim.reset: expected a finite pose (x, y, heading), got {pose!r}")
        if not (0 < pose[0] < self.maze.size and 0 < pose[1] < self.maze.size):
            raise ValueError(f"MazeSim.reset: pose {pose[:2]} lies outside the maze [0, {self.maze.size}]^2")
        self.pose = np.array([pose[0], pose[1], float(wrap_angle(pose[2]))])
        return self.pose.copy()

    def step(self, control) -> tuple[np.ndarray, bool]:
        """Rotate by ``control[0]``, then move ``control[1]`` (>= 0) along the new heading.

        Returns the new true pose and whether a wall cut the translation short.
        """
        d_alpha, d_p = (float(v) for v in np.asarray(control, float).reshape(2))
        if d_p < 0:
            raise ValueError(f"MazeSim.step: the agent moves only forward; got d_p = {d_p}")
        if self.noise.rot_std > 0:
            d_alpha += self.noise.rot_std * self.rng.standard_normal()
        if self.noise.trans_frac > 0 and d_p > 0:
            d_p = max(0.0, d_p * (1.0 + self.noise.trans_frac * self.rng.standard_normal()))
        heading = float(wrap_angle(self.pose[2] + d_alpha))
        moved = self.free_distance(self.pose[:2], heading, d_p)
        xy = self.pose[:2] + moved * np.array([np.cos(heading), np.sin(heading)])
        self.pose = np.array([xy[0], xy[1], heading])
        return self.pose.copy(), moved < d_p - 1e-12

    def close(self) -> None:
        if self.client is not None and self._p.isConnected(self.client):
            self._p.disconnect(self.client)
        self.client = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

"""`NavSim`: the Python API agents use (motion, sensors, odometry, faults, dynamic scenes).

Frames: `true_pose()` is the world frame; `odometry()` is the robot's dead-reckoned
estimate. Motion commands given in the odometry frame (`frame="odom"`, the default) are
executed the way a controller on the robot would execute them: relative to where the
robot believes it is. Panoramas are aligned to the odometry frame (view k looks along
odometry heading k * 360 / n_views), LiDAR beams to the robot frame (beam 0 forward).
The obstacle signal is given per odometry-frame heading k * 360 / n_directions.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .geometry import ShapeSet
from .layouts import Layout, make_layout
from .occupancy import OccupancyGrid, layout_grid
from .robot import (
    ROBOT_RADIUS,
    MoveResult,
    Odometry,
    OdometryNoise,
    odom_to_world,
    straight_move,
    wrap,
)
from .sensors import FaultSchedule, lidar_angles, obstacle_signal


@dataclass(frozen=True)
class SimConfig:
    """Robot, sensor and motion parameters (TurtleBot3-Waffle-like defaults)."""

    robot_radius: float = ROBOT_RADIUS
    robot_height: float = 0.2
    lidar_height: float = 0.2
    lidar_beams: int = 360
    lidar_range: float = 12.0
    camera_height: float = 0.35
    image_size: tuple[int, int] = (64, 64)  # (height, width) of one view
    n_views: int = 4
    n_directions: int = 12
    step_length: float = 0.5
    obstacle_margin: float = 0.05
    move_increment: float = 0.05
    resolution: float = 0.05
    noise: OdometryNoise = field(default_factory=OdometryNoise)

    @property
    def fov_deg(self) -> float:
        return 360.0 / self.n_views


class NavSim:
    """A layout in pybullet with a kinematic disc robot, LiDAR, panoramic camera, odometry."""

    def __init__(self, layout: Layout | str = "mini_warehouse", config: SimConfig | None = None,
                 seed: int | None = None, layout_seed: int = 0, start=None):
        from .world import PyBulletScene

        self.base_layout = make_layout(layout, layout_seed) if isinstance(layout, str) else layout
        self.config = config or SimConfig()
        self.scene = PyBulletScene(self.base_layout, self.config.robot_radius,
                                   self.config.robot_height)
        self.faults = FaultSchedule()
        self.reset(seed, start)

    # ----------------------------------------------------------------- lifecycle
    def reset(self, seed: int | np.random.Generator | None = None, start=None) -> np.ndarray:
        """Restore the layout, clear faults and scheduled moves, place the robot.

        `start` is a pose (x, y, yaw) or an index into `layout.starts`; by default the
        start is drawn from `layout.starts` with the seeded generator. Returns the true pose.
        """
        self.rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
        if getattr(self, "layout", None) is not self.base_layout:
            for s in self.base_layout.shapes:
                if self.layout_moved(s.name):
                    self.scene.move_body(s.name, s.x, s.y, getattr(s, "yaw", 0.0))
            self._set_layout(self.base_layout)
        self.faults.clear()
        self.scheduled: list[tuple[int, str, tuple, float | None]] = []
        if start is None:
            start = int(self.rng.integers(len(self.layout.starts)))
        if np.ndim(start) == 0:
            start = self.layout.starts[int(start)]
        self.pose = np.array(start, float)
        self.odom = Odometry(self.pose, self.config.noise, self.rng)
        self.step_count = 0
        self.path = [self.pose.copy()]
        self.odom_path = [self.odom.pose.copy()]
        self.scene.set_robot(self.pose)
        self._cache: dict = {}
        return self.pose.copy()

    def layout_moved(self, name: str) -> bool:
        cur = getattr(self, "layout", None)
        return cur is not None and cur.shape(name) != self.base_layout.shape(name)

    def _set_layout(self, layout: Layout) -> None:
        self.layout = layout
        self.shapes = ShapeSet(layout.shapes)
        self.grid: OccupancyGrid = layout_grid(layout, self.config.resolution)

    def close(self) -> None:
        self.scene.close()

    # ----------------------------------------------------------------- motion
    def true_pose(self) -> np.ndarray:
        return self.pose.copy()

    def odometry(self) -> np.ndarray | None:
        """Odometry pose (x, y, yaw), or None while the odometry stream is dropped."""
        if self.faults.dropped("odometry", self.step_count):
            return None
        return self.odom.pose.copy()

    def move_to(self, waypoint, frame: str = "odom") -> MoveResult:
        """Turn toward `waypoint` and drive straight to it, stopping before any collision.

        One call is one step (step counter, faults and scheduled obstacle moves advance).
        """
        wp = np.asarray(waypoint, float)[:2]
        if frame == "odom":
            target = odom_to_world(self.odom.pose, self.pose, wp)
        elif frame == "world":
            target = wp
        else:
            raise ValueError("frame must be 'odom' or 'world'")
        return self._drive(target)

    def move_heading(self, heading: float, distance: float | None = None) -> MoveResult:
        """Drive `distance` (default step_length) along an odometry-frame heading (rad)."""
        d = self.config.step_length if distance is None else float(distance)
        true_heading = heading + (self.pose[2] - self.odom.pose[2])
        return self._drive(self.pose[:2] + d * np.array([np.cos(true_heading),
                                                         np.sin(true_heading)]))

    def step_action(self, action: int) -> MoveResult:
        """Discrete action: 0..n_directions-1 = heading k * 360 / n, n_directions = stay."""
        n = self.config.n_directions
        if not 0 <= int(action) <= n:
            raise ValueError(f"action must be in [0, {n}]")
        if int(action) == n:
            return self.stay()
        return self.move_heading(2 * np.pi * int(action) / n)

    def stay(self) -> MoveResult:
        start = self.pose.copy()
        self._advance()
        return MoveResult(True, 0.0, 0.0, start, self.pose.copy())

    def _drive(self, target) -> MoveResult:
        start = self.pose.copy()
        delta = target - start[:2]
        req = float(np.hypot(*delta))
        blocked_by = None
        if req > 1e-9:
            heading = float(np.arctan2(delta[1], delta[0]))
            self.odom.rotate(float(wrap(heading - self.pose[2])))
            self.pose[2] = heading
            end, dist, ok, hit = straight_move(self.shapes, self.config.robot_radius,
                                               start[:2], target, self.config.move_increment)
            self.pose[:2] = end
            self.odom.translate(dist)
            if not ok:
                blocked_by = self._nearest_name(hit)
        else:
            dist, ok = 0.0, True
        self.scene.set_robot(self.pose)
        self._advance()
        return MoveResult(ok, dist, req, start, self.pose.copy(), blocked_by)

    def _nearest_name(self, xy) -> str | None:
        best, name = np.inf, None
        for s in self.layout.shapes:
            d = float(ShapeSet([s]).distance(xy)[0])
            if d < best:
                best, name = d, s.name
        return name

    def _advance(self) -> None:
        self.step_count += 1
        self._cache = {}
        due = [m for m in self.scheduled if m[0] <= self.step_count]
        self.scheduled = [m for m in self.scheduled if m[0] > self.step_count]
        for _, name, xy, yaw in due:
            self.move_obstacle(name, xy, yaw)
        self.path.append(self.pose.copy())
        self.odom_path.append(self.odom.pose.copy())

    def teleport(self, pose) -> None:
        """Kidnap the robot: the true pose changes, odometry does not notice."""
        self.pose = np.array(pose, float)
        self.scene.set_robot(self.pose)
        self._cache = {}
        self.path.append(self.pose.copy())

    # ----------------------------------------------------------------- scene changes
    def move_obstacle(self, name: str, xy, yaw: float | None = None) -> None:
        """Move a named shape now, in pybullet and in the occupancy grid."""
        self._set_layout(self.layout.with_moved(name, xy, yaw))
        s = self.layout.shape(name)
        self.scene.move_body(name, s.x, s.y, getattr(s, "yaw", 0.0))
        self._cache = {}

    def schedule_obstacle_move(self, name: str, xy, at_step: int,
                               yaw: float | None = None) -> None:
        """Move `name` once the step counter reaches `at_step`."""
        self.layout.shape(name)  # raises on unknown names
        self.scheduled.append((int(at_step), name, tuple(xy), yaw))

    def inject_fault(self, stream: str, start_step: int, length: int) -> None:
        """Drop `stream` ('lidar', 'camera' or 'odometry') for steps [start, start + length)."""
        self.faults.add(stream, start_step, length)

    # ----------------------------------------------------------------- sensors
    def lidar_angles(self) -> np.ndarray:
        return lidar_angles(self.config.lidar_beams)

    def _scan(self):
        if "scan" not in self._cache:
            c = self.config
            self._cache["scan"] = self.scene.cast(
                self.pose[:2], self.pose[2] + self.lidar_angles(), c.lidar_height,
                c.robot_radius + 0.01, c.lidar_range)
        return self._cache["scan"]

    def lidar(self) -> np.ndarray | None:
        """Ranges (m) from the robot centre per beam (robot frame), or None when dropped."""
        if self.faults.dropped("lidar", self.step_count):
            return None
        return self._scan()[0].copy()

    def lidar_hits(self) -> tuple[np.ndarray, list]:
        """World end points of all beams and the hit shape names (None = max range)."""
        ranges, ids = self._scan()
        a = self.pose[2] + self.lidar_angles()
        pts = self.pose[:2] + ranges[:, None] * np.stack([np.cos(a), np.sin(a)], 1)
        return pts, [self.scene.names.get(int(i)) if i >= 0 else None for i in ids]

    def obstacle_signal(self) -> np.ndarray | None:
        """Per odometry-frame direction k: 1 if the sector minimum range is below
        robot radius + step length + margin; None when the LiDAR is dropped."""
        ranges = self.lidar()
        if ranges is None:
            return None
        c = self.config
        headings = self.lidar_angles() + self.odom.pose[2]
        return obstacle_signal(ranges, headings, c.n_directions,
                               c.robot_radius + c.step_length + c.obstacle_margin)

    def panorama(self) -> np.ndarray | None:
        """(h, w * n_views, 3) uint8, views left to right turning clockwise from odometry
        heading +half a view; None when the camera is dropped."""
        if self.faults.dropped("camera", self.step_count):
            return None
        if "pano" not in self._cache:
            c = self.config
            h, w = c.image_size
            off = self.pose[2] - self.odom.pose[2]
            views = [self.scene.view(self.pose[:2], c.camera_height,
                                     off - 2 * np.pi * k / c.n_views, w, h, c.fov_deg)
                     for k in range(c.n_views)]
            self._cache["pano"] = np.concatenate(views, axis=1)
        return self._cache["pano"].copy()

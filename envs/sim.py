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

from cogmap.genmodel.numerics import wrap_angle

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
)
from .sensors import FaultInjection, FaultSchedule, lidar_angles, obstacle_signal


@dataclass(frozen=True)
class SimConfig:
    """Robot, sensor and motion parameters (TurtleBot3-Waffle-like defaults).

    Attributes
    ----------
    robot_radius : float
        Radius (m) of the disc robot used for collisions.
    robot_height : float
        Height (m) of the robot body.
    lidar_height : float
        Height (m) of the LiDAR plane.
    lidar_beams : int
        Beams per scan, evenly spaced over 360 degrees (default 360).
    lidar_range : float
        Maximum range (m), default 12.
    camera_height : float
        Height (m) of the panoramic camera.
    image_size : tuple of int
        ``(height, width)`` pixels of one view.
    n_views : int
        Views per panorama, default 4.
    n_directions : int
        Discrete move directions (the action set adds one stay action), default 12.
    step_length : float
        Length (m) of one discrete move, default 0.5.
    obstacle_margin : float
        Extra distance (m) in the obstacle signal's threshold.
    move_increment : float
        Spacing (m) of the collision checks along a move.
    resolution : float
        Cell size (m) of the ground-truth occupancy grid.
    noise : OdometryNoise
        Odometry error model (default perfect odometry).
    """

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
        """Horizontal field of view of one view, degrees (``360 / n_views``)."""
        return 360.0 / self.n_views


class NavSim(FaultInjection):
    """A layout in pybullet with a kinematic disc robot, LiDAR, panoramic camera and odometry.

    Parameters
    ----------
    layout : Layout or str, optional
        A layout, or the name of a built-in one (default ``"mini_warehouse"``).
    config : SimConfig, optional
        Robot and sensor parameters; default ``SimConfig()``.
    seed : int, optional
        Seed of the start draw and odometry noise.
    layout_seed : int, optional
        Seed passed to :func:`make_layout` for a named layout, default 0.
    start : array_like or int, optional
        Start pose ``(x, y, yaw)`` or an index into ``layout.starts``.
    """

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

        Parameters
        ----------
        seed : int or numpy.random.Generator or None, optional
            Seed (or generator) for the start draw and odometry noise.
        start : array_like or int, optional
            A pose ``(x, y, yaw)`` (metres, radians, world frame) or an index into ``layout.starts``; by
            default drawn from ``layout.starts`` with the seeded generator.

        Returns
        -------
        numpy.ndarray
            ``(3,)`` float true pose.
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
        """Whether the shape ``name`` is no longer where the base layout put it.

        Parameters
        ----------
        name : str
            Shape name.

        Returns
        -------
        bool
        """
        cur = getattr(self, "layout", None)
        return cur is not None and cur.shape(name) != self.base_layout.shape(name)

    def _set_layout(self, layout: Layout) -> None:
        self.layout = layout
        self.shapes = ShapeSet(layout.shapes)
        self.grid: OccupancyGrid = layout_grid(layout, self.config.resolution)

    def close(self) -> None:
        """Disconnect the pybullet scene."""
        self.scene.close()

    # ----------------------------------------------------------------- motion
    def true_pose(self) -> np.ndarray:
        """The true pose ``(x, y, yaw)`` in the world frame.

        Returns
        -------
        numpy.ndarray
            ``(3,)`` float, metres and radians (a copy).
        """
        return self.pose.copy()

    def odometry(self) -> np.ndarray | None:
        """The odometry pose ``(x, y, yaw)``, or None while the odometry stream is dropped.

        Returns
        -------
        numpy.ndarray or None
            ``(3,)`` float, metres and radians, odometry frame.
        """
        if self.faults.dropped("odometry", self.step_count):
            return None
        return self.odom.pose.copy()

    def move_to(self, waypoint, frame: str = "odom") -> MoveResult:
        """Turn toward ``waypoint`` and drive straight to it, stopping before any collision.

        One call is one step (step counter, faults and scheduled obstacle moves advance).

        Parameters
        ----------
        waypoint : array_like
            ``(x, y)`` in metres (extra entries ignored).
        frame : str, optional
            ``"odom"`` (default: relative to where the robot believes it is) or ``"world"``.

        Returns
        -------
        MoveResult
            Ground-truth outcome of the move.

        Raises
        ------
        ValueError
            For another frame.
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
        """Drive ``distance`` along an odometry-frame heading (one step).

        Parameters
        ----------
        heading : float
            Heading in radians, odometry frame.
        distance : float, optional
            Metres; default ``config.step_length``.

        Returns
        -------
        MoveResult
            Ground-truth outcome of the move.
        """
        d = self.config.step_length if distance is None else float(distance)
        true_heading = heading + (self.pose[2] - self.odom.pose[2])
        return self._drive(self.pose[:2] + d * np.array([np.cos(true_heading),
                                                         np.sin(true_heading)]))

    def step_action(self, action: int) -> MoveResult:
        """Discrete action: ``0 .. n_directions - 1`` move along heading ``k * 360 / n``; ``n_directions`` stays.

        Parameters
        ----------
        action : int
            Action index in ``[0, n_directions]``.

        Returns
        -------
        MoveResult
            As :meth:`move_to`.

        Raises
        ------
        ValueError
            If ``action`` is out of range.
        """
        n = self.config.n_directions
        if not 0 <= int(action) <= n:
            raise ValueError(f"action must be in [0, {n}]")
        if int(action) == n:
            return self.stay()
        return self.move_heading(2 * np.pi * int(action) / n)

    def stay(self) -> MoveResult:
        """Stay in place for one step (step counter, faults and scheduled moves advance).

        Returns
        -------
        MoveResult
            Ground-truth outcome of the move.
        """
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
            self.odom.rotate(float(wrap_angle(heading - self.pose[2])))
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
        """Kidnap the robot: the true pose changes, odometry does not notice.

        Parameters
        ----------
        pose : array_like
            ``(3,)`` float new true pose ``(x, y, yaw)``, metres and radians, world frame.
        """
        self.pose = np.array(pose, float)
        self.scene.set_robot(self.pose)
        self._cache = {}
        self.path.append(self.pose.copy())

    # ----------------------------------------------------------------- scene changes
    def move_obstacle(self, name: str, xy, yaw: float | None = None) -> None:
        """Move a named shape now, in pybullet and in the occupancy grid.

        Parameters
        ----------
        name : str
            Shape name.
        xy : array_like
            New centre ``(x, y)``, metres, world frame.
        yaw : float, optional
            New yaw in radians (boxes); default unchanged.
        """
        self._set_layout(self.layout.with_moved(name, xy, yaw))
        s = self.layout.shape(name)
        self.scene.move_body(name, s.x, s.y, getattr(s, "yaw", 0.0))
        self._cache = {}

    def schedule_obstacle_move(self, name: str, xy, at_step: int,
                               yaw: float | None = None) -> None:
        """Move ``name`` once the step counter reaches ``at_step``.

        Parameters
        ----------
        name : str
            Shape name (unknown names raise at once).
        xy : array_like
            New centre ``(x, y)``, metres.
        at_step : int
            Step at which the move happens.
        yaw : float, optional
            New yaw in radians.
        """
        self.layout.shape(name)  # raises on unknown names
        self.scheduled.append((int(at_step), name, tuple(xy), yaw))

    # ----------------------------------------------------------------- sensors
    def lidar_angles(self) -> np.ndarray:
        """Beam angles in the robot frame (beam 0 forward, counter-clockwise).

        Returns
        -------
        numpy.ndarray
            ``(lidar_beams,)`` float radians.
        """
        return lidar_angles(self.config.lidar_beams)

    def _scan(self):
        if "scan" not in self._cache:
            c = self.config
            self._cache["scan"] = self.scene.cast(
                self.pose[:2], self.pose[2] + self.lidar_angles(), c.lidar_height,
                c.robot_radius + 0.01, c.lidar_range)
        return self._cache["scan"]

    def lidar(self) -> np.ndarray | None:
        """Ranges from the robot centre per beam (robot frame), or None when the LiDAR is dropped.

        Returns
        -------
        numpy.ndarray or None
            ``(lidar_beams,)`` float metres (``lidar_range`` where nothing is hit).
        """
        if self.faults.dropped("lidar", self.step_count):
            return None
        return self._scan()[0].copy()

    def lidar_hits(self) -> tuple[np.ndarray, list]:
        """World end points of all beams and the names of the shapes they hit (ignores faults).

        Returns
        -------
        points : numpy.ndarray
            ``(lidar_beams, 2)`` float, metres, world frame.
        names : list of str or None
            Shape hit by each beam (None at maximum range).
        """
        ranges, ids = self._scan()
        a = self.pose[2] + self.lidar_angles()
        pts = self.pose[:2] + ranges[:, None] * np.stack([np.cos(a), np.sin(a)], 1)
        return pts, [self.scene.names.get(int(i)) if i >= 0 else None for i in ids]

    def obstacle_signal(self) -> np.ndarray | None:
        """Binary obstacle flag per odometry-frame direction ``k * 360 / n_directions``.

        A direction is blocked when the minimum range in its sector is below
        ``robot_radius + step_length + obstacle_margin``.

        Returns
        -------
        numpy.ndarray or None
            ``(n_directions,)`` int8, 1 = blocked; None when the LiDAR is dropped.
        """
        ranges = self.lidar()
        if ranges is None:
            return None
        c = self.config
        headings = self.lidar_angles() + self.odom.pose[2]
        return obstacle_signal(ranges, headings, c.n_directions,
                               c.robot_radius + c.step_length + c.obstacle_margin)

    def panorama(self) -> np.ndarray | None:
        """Panoramic camera image; None when the camera is dropped.

        Views are left to right turning clockwise from the odometry heading plus half a view.

        Returns
        -------
        numpy.ndarray or None
            ``(h, w * n_views, 3)`` uint8.
        """
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

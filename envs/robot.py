"""Kinematic disc robot: straight-line moves with collision checks, and drifting odometry."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from cogmap.genmodel.numerics import wrap_angle

from .geometry import ShapeSet

ROBOT_RADIUS = 0.22  # TurtleBot3 Waffle footprint (about 0.28 x 0.31 m) enclosed in a disc
#: largest |slip| of :class:`OdometryNoise` (a fraction of the distance: 0.5 reads 1.5 m per metre);
#: the drift studies go up to 0.15
MAX_SLIP = 0.5
#: largest |heading_bias| of :class:`OdometryNoise`, rad per metre travelled (about 29 degrees per
#: metre; the drift studies go up to 0.05)
MAX_HEADING_BIAS = 0.5
#: largest ``trans_std`` (m per sqrt m) and ``rot_std`` (rad per sqrt m) of :class:`OdometryNoise`
MAX_ODOMETRY_STD = 1.0


@dataclass
class MoveResult:
    """Outcome of one motion command (poses are ground truth ``(x, y, yaw)``).

    Attributes
    ----------
    success : bool
        False when the move stopped early before a collision.
    distance : float
        Distance travelled, metres.
    requested : float
        Distance requested, metres.
    start, end : numpy.ndarray
        ``(3,)`` float true poses (metres, metres, radians) before and after the move.
    blocked_by : str or None
        Name of the shape that blocked the move, if any.
    info : dict
        Extra information (empty unless a caller fills it).
    """

    success: bool
    distance: float
    requested: float
    start: np.ndarray
    end: np.ndarray
    blocked_by: str | None = None
    info: dict = field(default_factory=dict)


def straight_move(shapes: ShapeSet, radius: float, start_xy, target_xy,
                  increment: float = 0.05):
    """Advance from start toward target in `increment` steps while the disc stays clear.

    Returns (end_xy, travelled, success, blocking_point). The robot stops at the last
    sampled position whose clearance to every shape is at least `radius`.
    """
    start = np.asarray(start_xy, float)
    delta = np.asarray(target_xy, float) - start
    length = float(np.hypot(*delta))
    if length < 1e-9:
        return start.copy(), 0.0, True, None
    n = int(np.ceil(length / increment))
    s = np.minimum(np.arange(1, n + 1) * increment, length)
    pts = start + s[:, None] * (delta / length)
    bad = np.flatnonzero(shapes.distance(pts) < radius)
    if len(bad) == 0:
        return pts[-1].copy(), length, True, None
    i = int(bad[0])
    if i == 0:
        return start.copy(), 0.0, False, pts[0]
    return pts[i - 1].copy(), float(s[i - 1]), False, pts[i]


@dataclass(frozen=True)
class OdometryNoise:
    """Odometry error model (all zero = perfect odometry).

    Attributes
    ----------
    slip : float
        Fractional over-read of travelled distance (0.05 reports 1.05 m per true metre).
    heading_bias : float
        Yaw drift in radians per metre travelled.
    trans_std : float
        Random distance error, metres per sqrt(metre).
    rot_std : float
        Random yaw error, radians per sqrt(metre).
    """

    slip: float = 0.0
    heading_bias: float = 0.0
    trans_std: float = 0.0
    rot_std: float = 0.0

    def __post_init__(self):
        limits = {"slip": (-MAX_SLIP, MAX_SLIP, "MAX_SLIP"),
                  "heading_bias": (-MAX_HEADING_BIAS, MAX_HEADING_BIAS, "MAX_HEADING_BIAS"),
                  "trans_std": (0.0, MAX_ODOMETRY_STD, "MAX_ODOMETRY_STD"),
                  "rot_std": (0.0, MAX_ODOMETRY_STD, "MAX_ODOMETRY_STD")}
        for key, (lo, hi, name) in limits.items():
            v = getattr(self, key)
            if isinstance(v, bool) or not isinstance(v, int | float | np.integer | np.floating):
                raise ValueError(f"OdometryNoise.{key}: expected a number, got {v!r}")
            if not (np.isfinite(v) and lo <= v <= hi):
                raise ValueError(f"OdometryNoise.{key}: must be a finite number in [{lo:g}, {hi:g}] ({name}), "
                                 f"got {v!r}")


class Odometry:
    """Dead-reckoned pose integrated from true motion increments plus the noise model."""

    def __init__(self, pose, noise: OdometryNoise, rng: np.random.Generator):
        self.pose = np.asarray(pose, float).copy()
        self.noise = noise
        self.rng = rng
        self.travelled = 0.0

    def rotate(self, dtheta: float) -> None:
        """In-place rotation, measured exactly (gyro-aided)."""
        self.pose[2] = float(wrap_angle(self.pose[2] + dtheta))

    def translate(self, dist: float) -> None:
        """Forward motion of true length `dist` along the current heading."""
        nz = self.noise
        e_d, e_r = self.rng.standard_normal(2)
        root = np.sqrt(max(dist, 0.0))
        d = dist * (1.0 + nz.slip) + nz.trans_std * root * e_d
        dyaw = nz.heading_bias * dist + nz.rot_std * root * e_r
        mid = self.pose[2] + dyaw / 2
        self.pose[0] += d * np.cos(mid)
        self.pose[1] += d * np.sin(mid)
        self.pose[2] = float(wrap_angle(self.pose[2] + dyaw))
        self.travelled += dist


def odom_to_world(odom_pose, true_pose, xy_odom) -> np.ndarray:
    """Map a point given in the odometry frame to the world, using the current pose pair."""
    dth = true_pose[2] - odom_pose[2]
    c, s = np.cos(dth), np.sin(dth)
    d = np.asarray(xy_odom, float) - odom_pose[:2]
    return true_pose[:2] + np.array([c * d[0] - s * d[1], s * d[0] + c * d[1]])

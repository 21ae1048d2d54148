"""What the robot reports at one step (:class:`Sensed`), and the binary obstacle signal per action
direction from a 2-D LiDAR scan.

A heading is blocked when any LiDAR return falls inside the corridor the robot would sweep
moving one step along it: a rectangle of half-width ``robot radius + margin`` and length
``step + robot radius``. Unlike a minimum over an angular sector, the corridor catches a
wall corner beside the path at short range, and unlike a mean it is not fooled by the beams
that pass an obstacle.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def scan_points(ranges: np.ndarray, beam_angles: np.ndarray, max_range: float = 12.0) -> np.ndarray:
    """Returns of a scan as points relative to the robot (in the frame of ``beam_angles``)."""
    r = np.asarray(ranges, dtype=float)
    hit = np.isfinite(r) & (r < max_range - 1e-6)
    return r[hit, None] * np.stack([np.cos(beam_angles[hit]), np.sin(beam_angles[hit])], axis=1)


def sweep_points(ranges: np.ndarray, beam_angles: np.ndarray, max_range: float = 12.0) -> np.ndarray:
    """End point of every beam relative to the robot (in the frame of ``beam_angles``), in beam
    order: the return, or the point at ``max_range`` for a beam that hit nothing."""
    r = np.asarray(ranges, dtype=float)
    r = np.where(np.isfinite(r), np.minimum(r, max_range), max_range)
    return r[:, None] * np.stack([np.cos(beam_angles), np.sin(beam_angles)], axis=1)


def blocked(points: np.ndarray, moves: np.ndarray, half_width: float) -> np.ndarray:
    """For each move vector (relative to the robot), whether a return lies in its corridor."""
    moves = np.atleast_2d(np.asarray(moves, dtype=float))
    length = np.hypot(moves[:, 0], moves[:, 1])
    unit = moves / np.maximum(length, 1e-9)[:, None]
    along = points @ unit.T  # (points, moves)
    across = points @ np.stack([-unit[:, 1], unit[:, 0]])
    inside = (along > -half_width) & (along < length + half_width) & (np.abs(across) < half_width)
    return inside.any(axis=0)


def corridor_obstacles(ranges: np.ndarray, beam_angles: np.ndarray, num_headings: int, step: float,
                       half_width: float, max_range: float = 12.0) -> np.ndarray:
    """One bool per heading ``2 pi k / num_headings`` (angles in the same frame as the beams)."""
    h = 2 * np.pi * np.arange(num_headings) / num_headings
    moves = step * np.stack([np.cos(h), np.sin(h)], axis=1)
    return blocked(scan_points(ranges, beam_angles, max_range), moves, half_width)


@dataclass
class Sensed:
    """What the robot reports at one step; ``None`` marks a stream that did not report.

    The agent turns panorama, obstacle flags and scan into its belief frame before using them.

    Attributes
    ----------
    panorama : numpy.ndarray or None
        360-degree camera image, ``(H, W, 3)`` uint8 RGB (any image the encoder takes); None
        while the camera is silent.
    obstacles : numpy.ndarray or None
        ``(num_headings,)`` bool, one per heading (odometry frame): an obstacle lies within the
        move's corridor; None while the LiDAR is silent.
    odometry : numpy.ndarray or None
        ``(3,)`` float odometry pose ``(x, y, yaw)``, metres and radians; None while odometry is
        silent.
    moved : bool or None
        Outcome of the last motion command (False: the controller reported it blocked); None when
        no command was given.
    scan : numpy.ndarray or None
        ``(n, 2)`` float LiDAR returns relative to the robot, metres, axes of the odometry frame;
        optional (None: no scan, only the obstacle flags).
    sweep : numpy.ndarray or None
        ``(beams, 2)`` float end point of every beam in beam order (a beam that returned nothing
        ends at the LiDAR's range), relative to the robot, axes of the odometry frame: the area
        the scan swept, for the agent's sensed grid; optional (None: the grid is drawn from the
        returns' rays).
    """

    panorama: np.ndarray | None
    obstacles: np.ndarray | None  # one bool per heading: obstacle within reach
    odometry: np.ndarray | None  # (x, y, yaw) in the odometry frame
    moved: bool | None = None  # outcome of the last motion command (None: no command)
    scan: np.ndarray | None = None  # optional LiDAR returns relative to the robot (odometry frame, (n, 2))
    sweep: np.ndarray | None = None  # optional end points of every beam (max range where nothing returned)
    # the agent turns panorama, obstacles and scan into its belief frame before using them

    @property
    def missing(self) -> tuple[str, ...]:
        """The streams that did not report: a subset of ("camera", "lidar", "odometry")."""
        streams = (("camera", self.panorama), ("lidar", self.obstacles), ("odometry", self.odometry))
        return tuple(name for name, value in streams if value is None)

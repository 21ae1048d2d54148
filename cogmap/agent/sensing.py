"""Binary obstacle signal per action direction from a 2-D LiDAR scan.

A heading is blocked when any LiDAR return falls inside the corridor the robot would sweep
moving one step along it: a rectangle of half-width ``robot radius + margin`` and length
``step + robot radius``. Unlike a minimum over an angular sector, the corridor catches a
wall corner beside the path at short range, and unlike a mean it is not fooled by the beams
that pass an obstacle.
"""

from __future__ import annotations

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

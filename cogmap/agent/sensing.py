"""Binary obstacle signal per action direction from a 2-D LiDAR scan.

A heading is blocked when any LiDAR return falls inside the corridor the robot would sweep
moving one step along it: a rectangle of half-width ``robot radius + margin`` and length
``step + robot radius``. Unlike a minimum over an angular sector, the corridor catches a
wall corner beside the path at short range, and unlike a mean it is not fooled by the beams
that pass an obstacle.
"""

from __future__ import annotations

import numpy as np


def corridor_obstacles(ranges: np.ndarray, beam_angles: np.ndarray, num_headings: int, step: float,
                       half_width: float, max_range: float = 12.0) -> np.ndarray:
    """One bool per heading ``2 pi k / num_headings`` (angles in the same frame as the beams)."""
    r = np.asarray(ranges, dtype=float)
    hit = np.isfinite(r) & (r < max_range - 1e-6)
    pts = r[hit, None] * np.stack([np.cos(beam_angles[hit]), np.sin(beam_angles[hit])], axis=1)
    h = 2 * np.pi * np.arange(num_headings) / num_headings
    along = pts @ np.stack([np.cos(h), np.sin(h)])  # (points, headings)
    across = pts @ np.stack([-np.sin(h), np.cos(h)])
    inside = (along > -half_width) & (along < step + half_width) & (np.abs(across) < half_width)
    return inside.any(axis=0)

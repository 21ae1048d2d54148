"""Navigation metrics: LiDAR coverage, coverage efficiency, nAUC, drift, path-length ratios.

Coverage is the paper's: the free area seen by the LiDAR (12 m) over the ground-truth free
area. Each scan is filled as one polygon of its beam end points (not ray by ray, which leaves
gaps between beams far from the robot).
"""

from __future__ import annotations

import numpy as np


def _cv2():
    import cv2

    return cv2


def scan_mask(shape: tuple[int, int], origin, resolution: float, endpoints_xy: np.ndarray) -> np.ndarray:
    """Cells inside the polygon of beam end points (world x, y in beam order).

    Parameters
    ----------
    shape : tuple of int
        ``(rows, cols)`` of the grid.
    origin : sequence of float
        World ``(x, y)`` in metres of the grid's cell ``(0, 0)``.
    resolution : float
        Cell side in metres.
    endpoints_xy : numpy.ndarray, shape (n_beams, 2)
        World ``(x, y)`` of the beam end points in metres, in beam order (the polygon's vertices).

    Returns
    -------
    numpy.ndarray of bool, shape ``shape``
        True for the cells inside the filled polygon (row = y, column = x).
    """
    pts = np.asarray(endpoints_xy, dtype=float)
    cols = (pts[:, 0] - origin[0]) / resolution
    rows = (pts[:, 1] - origin[1]) / resolution
    poly = np.round(np.stack([cols, rows], axis=1)).astype(np.int32)
    mask = np.zeros(shape, dtype=np.uint8)
    _cv2().fillPoly(mask, [poly], 1)
    return mask.astype(bool)


class CoverageTracker:
    """Accumulates the free area seen by successive scans.

    ``free`` is the ground-truth free mask (cells reachable from the start); coverage is
    ``|seen & free| / |free|``.

    Parameters
    ----------
    free : numpy.ndarray of bool, shape (rows, cols)
        Ground-truth free cells (the denominator of coverage).
    origin : sequence of float
        World ``(x, y)`` in metres of cell ``(0, 0)``.
    resolution : float
        Cell side in metres.

    Attributes
    ----------
    seen : numpy.ndarray of bool, shape (rows, cols)
        Cells inside any scan polygon so far.
    total : float
        Number of free cells.
    """

    def __init__(self, free: np.ndarray, origin, resolution: float):
        self.free = np.asarray(free, dtype=bool)
        self.origin = origin
        self.resolution = resolution
        self.seen = np.zeros_like(self.free)
        self.total = float(self.free.sum())

    def update(self, endpoints_xy: np.ndarray) -> float:
        """Add one scan to the seen area.

        Parameters
        ----------
        endpoints_xy : numpy.ndarray, shape (n_beams, 2)
            World ``(x, y)`` in metres of the scan's beam end points, in beam order.

        Returns
        -------
        float
            Coverage in [0, 1] after this scan (:attr:`coverage`).
        """
        self.seen |= scan_mask(self.free.shape, self.origin, self.resolution, endpoints_xy)
        return self.coverage

    @property
    def coverage(self) -> float:
        """Seen free cells over all free cells, in [0, 1] (0.0 if there are no free cells)."""
        return float((self.seen & self.free).sum() / self.total) if self.total else 0.0

    @property
    def area(self) -> float:
        """Seen free area in square metres."""
        return float((self.seen & self.free).sum() * self.resolution**2)


def path_length(points) -> float:
    """Length of a polyline: the sum of its segments' Euclidean lengths in (x, y).

    Parameters
    ----------
    points : array_like, shape (n, >=2)
        Positions in metres; columns after the first two (e.g. yaw) are ignored.

    Returns
    -------
    float
        Length in metres; 0.0 for fewer than two points.
    """
    p = np.asarray(points, dtype=float)[:, :2]
    return float(np.hypot(*np.diff(p, axis=0).T).sum()) if len(p) > 1 else 0.0


def coverage_efficiency(area_m2: float, distance_m: float) -> float:
    """CE = area covered (m2) / distance travelled (m).

    Parameters
    ----------
    area_m2 : float
        Free area seen, in square metres.
    distance_m : float
        Distance travelled, in metres.

    Returns
    -------
    float
        Coverage efficiency in m2 per m; 0.0 if ``distance_m <= 0``.
    """
    return float(area_m2 / distance_m) if distance_m > 0 else 0.0


def nauc(distances, coverages, budget: float) -> float:
    """Normalised area under the coverage curve over distance in [0, budget] (coverage in [0, 1]).

    The curve is a step function (coverage holds until the next sample) and holds its last
    value up to the budget; 1.0 means full coverage from the first metre.

    Parameters
    ----------
    distances : array_like, shape (n,)
        Distance travelled at each sample, in metres, non-decreasing.
    coverages : array_like, shape (n,)
        Coverage in [0, 1] at each sample.
    budget : float
        Distance in metres over which the area is taken (samples beyond it are clipped).

    Returns
    -------
    float
        ``sum(width_i * coverage_i) / budget``, in [0, 1].

    Raises
    ------
    ValueError
        If ``budget <= 0``, there are no samples, or the distances decrease.
    """
    d = np.asarray(distances, dtype=float)
    c = np.asarray(coverages, dtype=float)
    if budget <= 0 or d.size == 0:
        raise ValueError("nauc needs a positive budget and at least one sample")
    if np.any(np.diff(d) < -1e-9):
        raise ValueError("distances must be non-decreasing")
    edges = np.clip(np.append(d, budget), 0, budget)
    widths = np.diff(edges)
    return float(np.sum(widths * c) / budget)


def rmse(estimate, truth) -> float:
    """Root mean square of the (x, y) position error.

    Parameters
    ----------
    estimate, truth : array_like, shape (n, >=2)
        Estimated and true positions in metres, row by row; extra columns (yaw) are ignored.

    Returns
    -------
    float
        ``sqrt(mean(|estimate - truth|^2))`` in metres.
    """
    e = np.asarray(estimate, dtype=float)[:, :2] - np.asarray(truth, dtype=float)[:, :2]
    return float(np.sqrt(np.mean(np.sum(e**2, axis=1))))


def ate_per_metre(estimate, truth) -> float:
    """Absolute trajectory error (RMSE) divided by the true distance travelled.

    Parameters
    ----------
    estimate, truth : array_like, shape (n, >=2)
        Estimated and true positions in metres, row by row.

    Returns
    -------
    float
        :func:`rmse` over :func:`path_length` of ``truth`` (metres per metre, dimensionless);
        0.0 if the true path has zero length.
    """
    length = path_length(truth)
    return rmse(estimate, truth) / length if length > 0 else 0.0

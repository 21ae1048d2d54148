"""Grid navigation shared by the baselines: coarse planning grids, shortest paths, waypoints.

Shortest paths come from one Dijkstra search from the robot over the 8-connected free cells
of a (coarse) grid (``scipy.sparse.csgraph``): the same optimal paths as A* with an
admissible heuristic, plus the path length to *every* cell, which tells at once which
frontiers or viewpoints are reachable. Diagonal steps may not cut an occupied corner.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage
from scipy.sparse.csgraph import dijkstra

from cogmap.planning.grid_graph import grid_graph


def coarsen(blocked: np.ndarray, factor: int) -> np.ndarray:
    """Max-pool a boolean grid by ``factor`` (a coarse cell is blocked if any fine cell is)."""
    if factor == 1:
        return np.asarray(blocked, bool)
    H, W = blocked.shape
    h, w = -(-H // factor), -(-W // factor)
    pad = np.zeros((h * factor, w * factor), bool)
    pad[:H, :W] = blocked
    return pad.reshape(h, factor, w, factor).any(axis=(1, 3))


def inflate(occupied: np.ndarray, radius_cells: float) -> np.ndarray:
    """Cells whose centre lies within ``radius_cells`` of an occupied cell centre."""
    if not occupied.any():
        return np.zeros_like(occupied, bool)
    return ndimage.distance_transform_edt(~occupied) <= radius_cells


def shortest_paths(blocked: np.ndarray, start_rc) -> tuple[np.ndarray, np.ndarray]:
    """Path length (cells) from ``start_rc`` to every cell and the predecessor array.

    Unreachable cells have length ``inf``; ``blocked`` cells are never entered (the start is
    always usable, so a robot squeezed against a wall can leave)."""
    H, W = blocked.shape
    free = ~np.asarray(blocked, bool)
    r0, c0 = int(start_rc[0]), int(start_rc[1])
    free[r0, c0] = True
    graph = grid_graph(free)
    dist, pred = dijkstra(graph, directed=False, indices=r0 * W + c0, return_predecessors=True)
    return dist.reshape(H, W), pred


def extract_path(pred: np.ndarray, shape: tuple[int, int], goal_rc) -> list[tuple[int, int]] | None:
    """Cell path from the search start to ``goal_rc`` (None when unreachable)."""
    W = shape[1]
    g = int(goal_rc[0]) * W + int(goal_rc[1])
    path = [g]
    while pred[path[-1]] >= 0:
        path.append(int(pred[path[-1]]))
    return [(p // W, p % W) for p in path[::-1]]


def line_free(blocked: np.ndarray, a_rc, b_rc) -> bool:
    """True when the straight segment between two cells crosses no blocked cell."""
    a, b = np.asarray(a_rc, float), np.asarray(b_rc, float)
    n = int(np.ceil(np.abs(b - a).max() * 2)) + 1
    t = np.linspace(0.0, 1.0, n)[:, None]
    pts = np.round(a + t * (b - a)).astype(int)
    H, W = blocked.shape
    if (pts < 0).any() or (pts[:, 0] >= H).any() or (pts[:, 1] >= W).any():
        return False
    inner = pts[1:]  # the start cell may touch an obstacle's inflation
    return not blocked[inner[:, 0], inner[:, 1]].any()


def next_waypoint(path_xy: np.ndarray, pos_xy, step: float, visible=None) -> np.ndarray:
    """The farthest path point at most ``step`` metres (straight line) from ``pos_xy`` that can
    be reached in a straight line (``visible(point) -> bool``) without skipping a path
    point that is farther than ``step`` along the path."""
    pos = np.asarray(pos_xy, float)
    best = path_xy[min(1, len(path_xy) - 1)]
    along = 0.0
    prev = pos
    for p in path_xy[1:]:
        along += float(np.hypot(*(p - prev)))
        prev = p
        if along > step + 1e-9 or np.hypot(*(p - pos)) > step + 1e-9:
            break
        if visible is None or visible(p):
            best = p
    return np.asarray(best, float)


def resample_path(points: np.ndarray, spacing: float) -> np.ndarray:
    """Points along a polyline every ``spacing`` metres (first and last kept)."""
    pts = np.asarray(points, float)
    if len(pts) < 2:
        return pts
    seg = np.hypot(*np.diff(pts, axis=0).T)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    if s[-1] <= 0:
        return pts[:1]
    q = np.append(np.arange(0.0, s[-1], spacing), s[-1])
    return np.stack([np.interp(q, s, pts[:, 0]), np.interp(q, s, pts[:, 1])], axis=1)

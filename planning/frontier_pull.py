"""A long-range pull for the DVBF-LM explorer: the way to the nearest edge of what the agent has sensed.

The mutual-information score of :mod:`.mi_exploration` looks ``T = 50`` steps ahead. Once the part
of the maze within that reach is known, every candidate scores about the same (the estimator's
noise) and nothing draws the agent toward the unexplored parts of a winding maze. This module gives
the agent a way there, built only from what it has itself: its estimated poses and the scans it
received at them.

* :func:`sweep` counts, per cell of a grid over ``[0, extent]^2``, the beams that crossed it and the
  beams that ended in it (a return shorter than the LiDAR range);
* :func:`cell_cost` prices each cell: a wall where ``hit_min`` or more returns ended and they are a
  fair share of the beams through it (hit/miss counts); passable where at least ``min_crossed`` beams
  crossed and no wall is in it or beside it (8-neighbours, :func:`blocked`); dearer within 3 cells of
  a wall, so paths keep to the middle of a corridor;
* :func:`frontier_distance` is the least path cost (8-connected Dijkstra) from every passable cell to
  the nearest frontier cell: passable, next to a cell not yet known (too few beams, not a wall);
* :func:`descend` follows that field downhill from the agent's cell, the cheapest path to the
  nearest frontier;
* :func:`pursue` turns a path into ``steps`` controls of the kinematic mean transition (turn toward a
  point ``lookahead`` ahead on the path, at most ``max_turn``; a full step), and :func:`free_steps`
  says how many of them stay out of :func:`blocked` cells.

How the explorer uses the result (taken instead of the best candidate when the candidates' mutual
information says nothing is left to learn within the horizon) is in :mod:`cogmap.dvbf.explore`.
Pure numpy and scipy; nothing here imports the agent layer.
"""

from __future__ import annotations

import numpy as np

from cogmap.genmodel.numerics import wrap_angle


def _cells(xy, extent: float, side: int) -> np.ndarray:
    """Integer ``(i, j)`` cells (``i`` along x) of world points ``xy (..., 2)``, clipped to the grid."""
    return np.clip(np.floor(np.asarray(xy, float) / extent * side).astype(np.int64), 0, side - 1)


def sweep(crossed, ended, poses, scans, lidar_range: float, extent: float, hit_fraction: float = 0.97) -> None:
    """Add the beams of ``scans (N, B)`` taken at ``poses (N, 3)`` to the counts, in place.

    Beam ``k`` points at ``heading + 2 pi k / B``. Samples every half cell up to half a cell short of
    the beam's end add to ``crossed``; the end cell of a beam shorter than ``hit_fraction *
    lidar_range`` adds to ``ended`` (longer beams hit nothing).

    Parameters
    ----------
    crossed, ended : numpy.ndarray, shape (side, side)
        Integer counts, indexed ``[i, j]`` with ``i`` along x; updated in place.
    poses : array_like, shape (N, 3)
        Poses ``(x, y, heading)`` the scans were taken at.
    scans : array_like, shape (N, B)
        Ranges in world units.
    lidar_range : float
        The LiDAR's range (what a beam that hits nothing returns).
    extent : float
        Side of the square world the grid covers.
    hit_fraction : float
        Beams at least this fraction of the range count as hitting nothing.

    Raises
    ------
    ValueError
        For mismatched shapes or a non-square count grid.
    """
    poses, scans = np.asarray(poses, float), np.asarray(scans, float)
    if poses.ndim != 2 or poses.shape[1] != 3 or scans.ndim != 2 or len(scans) != len(poses):
        raise ValueError(f"sweep: need poses (N, 3) and scans (N, B), got {poses.shape}, {scans.shape}")
    side = crossed.shape[0]
    if crossed.shape != (side, side) or ended.shape != crossed.shape:
        raise ValueError(f"sweep: crossed and ended must be the same square grid, got {crossed.shape}, {ended.shape}")
    if len(poses) == 0:
        return
    res = extent / side
    b = scans.shape[1]
    ang = poses[:, 2:3] + 2 * np.pi * np.arange(b) / b
    unit = np.stack([np.cos(ang), np.sin(ang)], -1)  # (N, B, 2)
    t = np.arange(0.0, lidar_range, res / 2)
    ok = t[None, None, :] < scans[..., None] - res / 2  # (N, B, S)
    pts = poses[:, None, None, :2] + unit[:, :, None, :] * t[None, None, :, None]
    ij = _cells(pts[ok], extent, side)
    # one count per beam and cell, not per sample
    beam = np.broadcast_to(np.arange(ok.shape[0] * b).reshape(ok.shape[0], b, 1), ok.shape)[ok]
    key = np.unique(np.stack([beam, ij[:, 0], ij[:, 1]], 1), axis=0)
    np.add.at(crossed, (key[:, 1], key[:, 2]), 1)
    hit = scans < hit_fraction * lidar_range
    end = _cells(poses[:, None, :2] + scans[..., None] * unit, extent, side)[hit]
    np.add.at(ended, (end[:, 0], end[:, 1]), 1)


def _walls(crossed, ended, hit_min: int, wall_fraction: float) -> np.ndarray:
    """Cells where ``hit_min`` or more returns ended, at least ``wall_fraction`` of the beams through them."""
    return (ended >= hit_min) & (ended >= wall_fraction * (ended + crossed))


def cell_cost(crossed, ended, hit_min: int = 2, min_crossed: int = 3, near_wall: float = 3.0,
              wall_fraction: float = 0.3) -> np.ndarray:
    """Cost per unit length of a path through each cell (inf: impassable).

    A cell is a wall when ``hit_min`` or more returns ended in it (one stray return does not make a
    wall) and they are at least ``wall_fraction`` of the beams that ended in it or crossed it (the
    hit/miss count of an occupancy grid: returns smeared by pose error into a doorway that many beams
    crossed do not close it). A cell is passable when at least ``min_crossed`` beams crossed it (a single beam through a
    gap in a wall does not open a way) and no wall is in it or beside it (8-neighbours). Passable
    cells within 3 cells of a wall cost ``near_wall`` per unit length, the others 1, so that paths keep
    to the middle of a corridor.

    Parameters
    ----------
    crossed, ended : numpy.ndarray, shape (side, side)
        Counts of :func:`sweep`.
    hit_min : int
        Returns that make a cell a wall.
    min_crossed : int
        Beams that must have crossed a passable cell.
    near_wall : float
        Cost of a passable cell close to a wall.
    wall_fraction : float
        Least fraction of returns among the beams through a cell that makes it a wall.

    Returns
    -------
    numpy.ndarray, shape (side, side)
        1, ``near_wall`` or inf.
    """
    from scipy.ndimage import distance_transform_edt

    crossed, ended = np.asarray(crossed), np.asarray(ended)
    wall = _walls(crossed, ended, hit_min, wall_fraction)
    clear = distance_transform_edt(~wall) if wall.any() else np.full(wall.shape, np.inf)
    cost = np.where(clear <= 3.0, near_wall, 1.0)
    return np.where((crossed >= min_crossed) & (clear > 1.5), cost, np.inf)


def blocked(crossed, ended, hit_min: int = 2, wall_fraction: float = 0.3) -> np.ndarray:
    """Wall cells and their 8-neighbours (where :func:`cell_cost` allows no path whatever the beams).

    Parameters
    ----------
    crossed, ended : numpy.ndarray, shape (side, side)
        Counts of :func:`sweep`.
    hit_min, wall_fraction
        As in :func:`cell_cost`.

    Returns
    -------
    numpy.ndarray of bool, shape (side, side)
    """
    wall = np.pad(_walls(np.asarray(crossed), np.asarray(ended), hit_min, wall_fraction), 1)
    n = wall.shape[0] - 2
    out = np.zeros((n, n), bool)
    for di in (0, 1, 2):
        for dj in (0, 1, 2):
            out |= wall[di:di + n, dj:dj + n]
    return out


def free_steps(positions, mask, extent: float) -> int:
    """Steps of a path ``positions (T + 1, 2)`` (its first point the start) before it enters a cell of
    ``mask`` (e.g. :func:`blocked`); ``T`` when it never does.

    Parameters
    ----------
    positions : array_like, shape (T + 1, 2)
        World positions, the start first.
    mask : numpy.ndarray of bool, shape (side, side)
        Cells the path must not enter.
    extent : float
        Side of the world.

    Returns
    -------
    int
    """
    ij = _cells(np.asarray(positions, float)[1:], extent, mask.shape[0])
    hit = mask[ij[:, 0], ij[:, 1]]
    return int(hit.argmax()) if hit.any() else len(ij)


def frontier_distance(crossed, ended, hit_min: int = 2, min_crossed: int = 3, near_wall: float = 3.0,
                      wall_fraction: float = 0.3) -> tuple[np.ndarray, np.ndarray]:
    """Least path cost from every passable cell to the nearest frontier cell.

    A frontier cell is passable (:func:`cell_cost`) with a 4-neighbour inside the grid that is not yet
    known: crossed by fewer than ``min_crossed`` beams and not a wall. Paths are 8-connected over passable
    cells, a diagonal step needs both side cells passable; a step costs its length (1 or sqrt(2) cells)
    times the mean cost of its two cells.

    Parameters
    ----------
    crossed, ended : numpy.ndarray, shape (side, side)
        Counts of :func:`sweep`.
    hit_min, min_crossed, near_wall, wall_fraction
        As in :func:`cell_cost`.

    Returns
    -------
    dist : numpy.ndarray, shape (side, side)
        Path cost in cell lengths; inf where no frontier is reachable or the cell is impassable.
    cost : numpy.ndarray, shape (side, side)
        The cell costs the paths were priced with (for :func:`descend`).
    """
    from scipy.sparse.csgraph import dijkstra

    from .grid_graph import grid_graph

    crossed, ended = np.asarray(crossed), np.asarray(ended)
    cost = cell_cost(crossed, ended, hit_min, min_crossed, near_wall, wall_fraction)
    ok = np.isfinite(cost)
    unknown = (crossed < min_crossed) & ~_walls(crossed, ended, hit_min, wall_fraction)
    pad = np.pad(unknown, 1, constant_values=False)  # outside the world is not unexplored
    frontier = ok & (pad[:-2, 1:-1] | pad[2:, 1:-1] | pad[1:-1, :-2] | pad[1:-1, 2:])
    n = ok.shape[0]
    if not frontier.any():
        return np.full(ok.shape, np.inf), cost
    graph = grid_graph(ok, cost)
    d = dijkstra(graph, directed=False, indices=np.flatnonzero(frontier.ravel()), min_only=True)
    return np.where(ok.ravel(), d, np.inf).reshape(n, n), cost


def descend(dist, cost, start_xy, extent: float, max_cells: int = 10_000) -> np.ndarray:
    """The path down ``dist`` from the cell of ``start_xy`` to a frontier cell (distance 0).

    From an impassable start cell (beside a wall, or not yet crossed by enough beams) the walk
    first steps to the passable cell within 3 cells that has the least distance.

    Parameters
    ----------
    dist, cost : numpy.ndarray, shape (side, side)
        Output of :func:`frontier_distance`.
    start_xy : array_like, shape (2,)
        World position of the agent.
    extent : float
        Side of the world.
    max_cells : int
        Safety bound on the path length.

    Returns
    -------
    numpy.ndarray, shape (k, 2)
        World positions of the cell centres along the path (empty if no frontier is reachable).
    """
    n = dist.shape[0]
    i, j = _cells(start_xy, extent, n)
    if not np.isfinite(dist[i, j]):
        lo_i, lo_j = max(i - 3, 0), max(j - 3, 0)
        win = dist[lo_i:i + 4, lo_j:j + 4]
        if not np.isfinite(win).any():
            return np.zeros((0, 2))
        a, b = np.unravel_index(np.argmin(win), win.shape)
        i, j = lo_i + a, lo_j + b
    path = [(i, j)]
    for _ in range(max_cells):
        if dist[i, j] == 0:
            break
        # the neighbour on a cheapest path: least distance plus step cost, no corner cutting
        best, nxt = dist[i, j] + 1e-9, None
        for di in (-1, 0, 1):
            for dj in (-1, 0, 1):
                a, b = i + di, j + dj
                if not ((di or dj) and 0 <= a < n and 0 <= b < n):
                    continue
                if di and dj and not (np.isfinite(dist[a, j]) and np.isfinite(dist[i, b])):
                    continue
                v = dist[a, b] + (np.sqrt(2.0) if di and dj else 1.0) * 0.5 * (cost[i, j] + cost[a, b])
                if v < best:
                    best, nxt = v, (a, b)
        if nxt is None:
            break
        i, j = nxt
        path.append(nxt)
    return (np.array(path, float) + 0.5) * (extent / n)


def pursue(path_xy, pose, steps: int, max_turn: float, max_step: float, lookahead: float | None = None,
           first_turn: float = np.pi) -> np.ndarray:
    """Controls that follow ``path_xy`` from ``pose`` under the kinematic mean transition.

    Each step turns toward the path point ``lookahead`` (default 3 steps) beyond the path point
    nearest the current position, at most ``max_turn`` (the first step at most ``first_turn``, as the
    mutual-information candidates may), then moves ``max_step`` (rotation before translation, as the
    maze world applies them). After the path's end the controls go straight on.

    Parameters
    ----------
    path_xy : array_like, shape (k, 2)
        Path positions, first near the pose.
    pose : array_like, shape (3,)
        Start ``(x, y, heading)``.
    steps : int
        Number of controls.
    max_turn, max_step : float
        Control bounds per step.
    lookahead : float, optional
        Distance along the path to steer at.
    first_turn : float
        Bound of the first turn.

    Returns
    -------
    numpy.ndarray, shape (steps, 2)
        ``(turn, forward)`` per step.

    Raises
    ------
    ValueError
        For an empty path or ``steps < 1``.
    """
    path = np.asarray(path_xy, float).reshape(-1, 2)
    if path.shape[0] == 0 or steps < 1:
        raise ValueError(f"pursue: need a non-empty path and steps >= 1, got {path.shape[0]} points, {steps}")
    look = 3 * max_step if lookahead is None else lookahead
    seg = np.r_[0.0, np.cumsum(np.hypot(*np.diff(path, axis=0).T))]
    x, y, h = (float(v) for v in np.asarray(pose, float)[:3])
    out = np.zeros((steps, 2))
    for t in range(steps):
        k = int(np.argmin(np.hypot(path[:, 0] - x, path[:, 1] - y)))
        m = min(int(np.searchsorted(seg, seg[k] + look)), len(path) - 1)
        tx, ty = path[m]
        if np.hypot(tx - x, ty - y) < 1e-9:
            turn = 0.0
        else:
            err = np.arctan2(ty - y, tx - x) - h
            bound = first_turn if t == 0 else max_turn
            turn = float(np.clip(wrap_angle(err), -bound, bound))
        h += turn
        x, y = x + max_step * np.cos(h), y + max_step * np.sin(h)
        out[t] = turn, max_step
    return out

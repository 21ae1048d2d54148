"""A coarse "sensed" grid: which parts of the plane the LiDAR has already swept.

Pure functions over a small value type. The agent shell owns the grid and feeds it every scan
(points relative to the robot, already turned into the belief frame); planning asks, for each
state of the map, how much free space a view from its pose would still reveal (the unseen area
of :func:`unseen_area`). That number is what makes the information gain of visiting a state
depend on what the robot has already sensed (``efe.sensed_info_gain``) and which states still
promise information (the preferred states of the inductive term in exploration).

Cells are ``UNKNOWN`` (0), ``FREE`` (1) or ``OCCUPIED`` (2). Rays of a scan mark the cells they
cross free and the cell of their return occupied (an occupied cell stays occupied). The grid
grows (by whole chunks) when a scan or a query leaves it.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

UNKNOWN, FREE, OCCUPIED = 0, 1, 2


class SensedGrid(NamedTuple):
    cells: np.ndarray  # (H, W) int8: UNKNOWN / FREE / OCCUPIED; row = y, column = x
    origin: np.ndarray  # world (x, y) of the corner of cell (0, 0)
    resolution: float  # cell size (m)


def empty(center, resolution: float = 0.2, half_size: float = 8.0) -> SensedGrid:
    """An all-unknown square grid of side ``2 * half_size`` around ``center``."""
    if resolution <= 0 or half_size <= 0:
        raise ValueError("resolution and half_size must be positive")
    n = int(np.ceil(2 * half_size / resolution))
    origin = np.asarray(center, dtype=float)[:2] - half_size
    return SensedGrid(np.zeros((n, n), dtype=np.int8), origin, float(resolution))


def to_cells(grid: SensedGrid, xy) -> np.ndarray:
    """(row, col) integer cells of world points ``xy`` (..., 2)."""
    xy = np.asarray(xy, dtype=float)
    c = np.floor((xy[..., 0] - grid.origin[0]) / grid.resolution).astype(np.int64)
    r = np.floor((xy[..., 1] - grid.origin[1]) / grid.resolution).astype(np.int64)
    return np.stack([r, c], axis=-1)


def ensure(grid: SensedGrid, xy, margin: float = 2.0, chunk: float = 4.0) -> SensedGrid:
    """The same grid, padded with unknown cells (in chunks) so that every point of ``xy`` lies
    at least ``margin`` inside it."""
    xy = np.atleast_2d(np.asarray(xy, dtype=float))
    res = grid.resolution
    H, W = grid.cells.shape
    lo = xy.min(axis=0) - margin
    hi = xy.max(axis=0) + margin
    top = grid.origin + np.array([W, H]) * res
    k = max(1, int(round(chunk / res)))
    pad_lo = np.where(lo < grid.origin, np.ceil((grid.origin - lo) / res / k) * k, 0).astype(int)
    pad_hi = np.where(hi > top, np.ceil((hi - top) / res / k) * k, 0).astype(int)
    if not (pad_lo.any() or pad_hi.any()):
        return grid
    cells = np.pad(grid.cells, ((pad_lo[1], pad_hi[1]), (pad_lo[0], pad_hi[0])), constant_values=UNKNOWN)
    return SensedGrid(cells, grid.origin - pad_lo * res, res)


def mark_scan(grid: SensedGrid, robot_xy, points_xy) -> SensedGrid:
    """Add one scan: ``points_xy`` (n, 2) are the returns in the grid's (belief) frame, taken
    from ``robot_xy``. Cells along each ray become free, the return's cell occupied."""
    robot_xy = np.asarray(robot_xy, dtype=float)[:2]
    pts = np.asarray(points_xy, dtype=float).reshape(-1, 2)
    grid = ensure(grid, np.vstack([robot_xy[None, :], pts]))
    cells = grid.cells.copy()
    res = grid.resolution
    if pts.shape[0]:
        rel = pts - robot_xy
        length = np.hypot(rel[:, 0], rel[:, 1])
        step = res / 2
        t = np.arange(0.0, max(float(length.max()), step), step)
        # samples strictly before the return (half a cell short), per ray
        ok = t[None, :] < (length[:, None] - res / 2)
        unit = rel / np.maximum(length, 1e-9)[:, None]
        samples = robot_xy + unit[:, None, :] * t[None, :, None]
        rc = to_cells(grid, samples[ok])
        cells[rc[:, 0], rc[:, 1]] = np.maximum(cells[rc[:, 0], rc[:, 1]], FREE)
    return _returns_and_robot(grid, cells, robot_xy, pts)


def _returns_and_robot(grid: SensedGrid, cells: np.ndarray, robot_xy, returns_xy) -> SensedGrid:
    """Finish a scan on ``cells`` (a copy of ``grid.cells``): the returns' cells occupied, the
    robot's own cell free if it was unknown."""
    if returns_xy.shape[0]:
        hit = to_cells(grid, returns_xy)
        cells[hit[:, 0], hit[:, 1]] = OCCUPIED
    here = to_cells(grid, robot_xy)
    if cells[here[0], here[1]] == UNKNOWN:
        cells[here[0], here[1]] = FREE
    return SensedGrid(cells, grid.origin, grid.resolution)


def mark_sweep(grid: SensedGrid, robot_xy, ends_xy, returns_xy=None) -> SensedGrid:
    """Add one scan as the area it swept: the polygon of its beam end points ``ends_xy`` (n, 2),
    in beam order, beams that returned nothing ending at the LiDAR's range, is free; the cells of
    ``returns_xy`` (k, 2) are occupied (an occupied cell stays occupied). This is the area the
    coverage of the studies counts as seen (``cogmap.metrics.scan_mask``), with no gaps between
    diverging beams. The polygon is star-shaped around the robot, so a cell is inside when it
    lies on the robot's side of the edge between the two end points whose beams bracket it.
    """
    robot_xy = np.asarray(robot_xy, dtype=float)[:2]
    ends = np.asarray(ends_xy, dtype=float).reshape(-1, 2)
    rets = np.zeros((0, 2)) if returns_xy is None else np.asarray(returns_xy, dtype=float).reshape(-1, 2)
    grid = ensure(grid, np.vstack([robot_xy[None, :], ends, rets]))
    cells = grid.cells.copy()
    res = grid.resolution
    if ends.shape[0] >= 3:
        rel = ends - robot_xy
        ang = np.arctan2(rel[:, 1], rel[:, 0])
        order = np.argsort(ang, kind="stable")
        rel, ang = rel[order], ang[order]
        lo = to_cells(grid, robot_xy + rel.min(axis=0))
        hi = to_cells(grid, robot_xy + rel.max(axis=0))
        rr, cc = np.mgrid[lo[0]:hi[0] + 1, lo[1]:hi[1] + 1]
        p = grid.origin + (np.stack([cc, rr], axis=-1) + 0.5) * res - robot_xy  # cell centres
        a = np.arctan2(p[..., 1], p[..., 0])
        i = np.searchsorted(ang, a, side="right") - 1  # wedge [ang[i], ang[i + 1]), cyclic
        i = np.where(i < 0, ang.size - 1, i)
        wedge = np.roll(rel, -1, axis=0) - rel  # edge from each end point to the next
        side = wedge[:, 0] * (-rel[:, 1]) - wedge[:, 1] * (-rel[:, 0])  # the robot's side of each edge
        e0, edge, cross_robot = rel[i], wedge[i], side[i]
        # the cell centre on the robot's side of the edge e0 -> e1, or within half a cell of the edge
        # itself (a cell the boundary passes through counts, as for a filled polygon)
        cross_cell = edge[..., 0] * (p[..., 1] - e0[..., 1]) - edge[..., 1] * (p[..., 0] - e0[..., 0])
        t = np.clip(((p - e0) * edge).sum(axis=-1) / np.maximum((edge**2).sum(axis=-1), 1e-12), 0.0, 1.0)
        near = np.hypot(*np.moveaxis(p - e0 - t[..., None] * edge, -1, 0)) <= 0.5 * res
        inside = (cross_cell * cross_robot >= 0) | near
        sub = cells[lo[0]:hi[0] + 1, lo[1]:hi[1] + 1]
        sub[inside & (sub == UNKNOWN)] = FREE
    return _returns_and_robot(grid, cells, robot_xy, rets)


def changed_bounds(before: SensedGrid, after: SensedGrid):
    """World box ``(xmin, ymin, xmax, ymax)`` of the cells whose value differs between two grids
    over the same cells (``after = mark_scan(ensure(before, ...), ...)``), or None."""
    if before.cells.shape != after.cells.shape or not np.allclose(before.origin, after.origin):
        raise ValueError("changed_bounds() compares two grids over the same cells")
    r, c = np.nonzero(before.cells != after.cells)
    if r.size == 0:
        return None
    res = after.resolution
    lo = after.origin + np.array([c.min(), r.min()]) * res
    hi = after.origin + np.array([c.max() + 1, r.max() + 1]) * res
    return (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))


def box_within(xy, box, radius: float) -> np.ndarray:
    """Per point (n, 2): whether the box ``(xmin, ymin, xmax, ymax)`` comes within ``radius``."""
    xy = np.atleast_2d(np.asarray(xy, dtype=float))
    if box is None:
        return np.zeros(xy.shape[0], dtype=bool)
    dx = np.maximum(np.maximum(box[0] - xy[:, 0], xy[:, 0] - box[2]), 0.0)
    dy = np.maximum(np.maximum(box[1] - xy[:, 1], xy[:, 1] - box[3]), 0.0)
    return dx**2 + dy**2 <= radius**2


def merge_boxes(a, b):
    """Smallest box holding both (either may be None)."""
    if a is None:
        return b
    if b is None:
        return a
    return (min(a[0], b[0]), min(a[1], b[1]), max(a[2], b[2]), max(a[3], b[3]))


def ray_offsets(radius: float, rays: int, step: float) -> tuple[np.ndarray, np.ndarray]:
    """Sample offsets (rays, samples, 2) of a fan of ``rays`` rays up to ``radius`` and the area
    (m2) each sample stands for (the annular wedge ``r dr dtheta`` around it)."""
    a = 2 * np.pi * np.arange(rays) / rays
    r = np.arange(step, radius + 1e-9, step)
    off = r[None, :, None] * np.stack([np.cos(a), np.sin(a)], axis=1)[:, None, :]
    return off, r * step * (2 * np.pi / rays)


def opaque(grid: SensedGrid) -> np.ndarray:
    """Cells that stop an imagined ray: occupied cells grown by one cell (3 x 3), so a ray cannot
    slip diagonally between the cells of a wall the scans drew as a staircase."""
    occ = grid.cells == OCCUPIED
    out = occ.copy()
    out[1:, :] |= occ[:-1, :]
    out[:-1, :] |= occ[1:, :]
    grown = out.copy()
    grown[:, 1:] |= out[:, :-1]
    grown[:, :-1] |= out[:, 1:]
    return grown


def _view_codes(grid: SensedGrid) -> np.ndarray:
    """Per cell, padded by a ring of unknown cells (cells outside the grid are unknown and
    transparent): bit 1 unknown, bit 2 :func:`opaque`."""
    codes = (grid.cells == UNKNOWN).astype(np.uint8) | (opaque(grid).astype(np.uint8) << 1)
    return np.pad(codes, 1, constant_values=1)


def check_bounds(bounds, owner: str) -> tuple[float, float, float, float]:
    """``bounds`` as a tuple ``(xmin, ymin, xmax, ymax)`` of finite floats with xmin < xmax and
    ymin < ymax; ValueError naming ``owner`` otherwise."""
    try:
        b = tuple(float(v) for v in bounds)
    except (TypeError, ValueError):
        b = ()
    if len(b) != 4 or not np.all(np.isfinite(b)) or b[0] >= b[2] or b[1] >= b[3]:
        raise ValueError(f"{owner}: bounds must be (xmin, ymin, xmax, ymax) with xmin < xmax and ymin < ymax, "
                         f"got {bounds!r}")
    return b


def inside_bounds(xy, bounds) -> np.ndarray:
    """Whether each point of ``xy`` (..., 2) lies within ``bounds`` ``(xmin, ymin, xmax, ymax)``."""
    xy = np.asarray(xy, dtype=float)
    x0, y0, x1, y1 = bounds
    return (xy[..., 0] >= x0) & (xy[..., 0] <= x1) & (xy[..., 1] >= y0) & (xy[..., 1] <= y1)


def view_weights(grid: SensedGrid, xy, radius: float = 6.0, rays: int = 48, skip: float = 0.3,
                 free_path: float = np.inf, bounds=None) -> tuple[np.ndarray, np.ndarray]:
    """The samples of the imagined views from the viewpoints ``xy`` (n, 2) and the unknown area
    (m2) each stands for (:func:`unseen_area` is their sum per viewpoint; a sample that is not
    unknown, or not visible, or outside ``bounds`` ``(xmin, ymin, xmax, ymax)`` when given,
    weighs 0).

    Returns
    -------
    points : numpy.ndarray, shape (n, rays, samples, 2)
        World positions of the samples.
    weights : numpy.ndarray, shape (n, rays, samples)
        Unseen area per sample (m2), visibility and ``free_path`` included.
    """
    xy = np.atleast_2d(np.asarray(xy, dtype=float))
    off, w = ray_offsets(radius, rays, grid.resolution)
    points = xy[:, None, None, :] + off[None]
    rc = to_cells(grid, points)  # (n, rays, samples, 2)
    codes = _view_codes(grid)  # one gather: the padding ring stands for every cell outside the grid
    code = codes[np.clip(rc[..., 0] + 1, 0, codes.shape[0] - 1), np.clip(rc[..., 1] + 1, 0, codes.shape[1] - 1)]
    unknown = (code & 1).astype(bool)
    wall = (code & 2).astype(bool)
    near = (np.arange(off.shape[1]) + 1) * grid.resolution <= skip
    unknown[:, :, near] = False
    wall[:, :, near] = False
    # a sample is visible while no opaque sample lies before it (or on it) on its ray
    blocked = np.cumsum(wall, axis=2) > 0
    seen = unknown & ~blocked
    if np.isfinite(free_path):
        hidden = np.cumsum(seen, axis=2) * grid.resolution  # unknown metres up to each sample
        weight = seen * np.exp(-hidden / free_path) * w[None, None, :]
    else:
        weight = seen * w[None, None, :]
    if bounds is not None:  # a known outline: nothing to see beyond it
        weight = weight * inside_bounds(points, bounds)
    return points, weight


def unseen_area(grid: SensedGrid, xy, radius: float = 6.0, rays: int = 48, skip: float = 0.3,
                free_path: float = np.inf, bounds=None) -> np.ndarray:
    """Per viewpoint of ``xy`` (n, 2): the unknown area (m2) a scan of range ``radius`` from it
    would sweep, with occupied cells (grown by one cell, :func:`opaque`) opaque; cells outside the
    grid are unknown. Unknown cells are transparent by default; with a finite ``free_path`` (m)
    each is occupied with a small independent chance, so a sample behind ``u`` metres of unknown
    cells (itself included) counts ``exp(-u / free_path)``, the chance that nothing unknown hides
    it. Samples within ``skip`` of the viewpoint (the robot's own footprint) neither count nor
    block. With ``bounds`` ``(xmin, ymin, xmax, ymax)`` (the space's outline, when known) samples
    beyond it do not count. Where that area lies: :func:`view_weights`."""
    xy = np.atleast_2d(np.asarray(xy, dtype=float))
    if xy.shape[0] == 0:
        return np.zeros(0)
    return view_weights(grid, xy, radius, rays, skip, free_path, bounds)[1].sum(axis=(1, 2))


def view_area(radius: float = 6.0, rays: int = 48, resolution: float = 0.2, skip: float = 0.3,
              free_path: float = np.inf) -> float:
    """Area a view of :func:`unseen_area` stands for in an unknown, unobstructed plane (its
    largest value), used to turn unseen areas into fractions."""
    off, w = ray_offsets(radius, rays, resolution)
    near = (np.arange(off.shape[1]) + 1) * resolution <= skip
    weight = np.ones(w.size)
    if np.isfinite(free_path):
        weight = np.exp(-np.cumsum(~near) * resolution / free_path)
    return float(rays * (w * weight)[~near].sum())


def frontier_points(grid: SensedGrid, spacing: float = 1.0) -> np.ndarray:
    """World points (m, 2) of the frontier, thinned to one per ``spacing`` square: free cells
    with an unknown 4-neighbour (the edge of what the scans have swept)."""
    cells = grid.cells
    unk = np.pad(cells == UNKNOWN, 1, constant_values=True)
    near_unknown = unk[:-2, 1:-1] | unk[2:, 1:-1] | unk[1:-1, :-2] | unk[1:-1, 2:]
    r, c = np.nonzero((cells == FREE) & near_unknown)
    if r.size == 0:
        return np.zeros((0, 2))
    k = max(1, int(round(spacing / grid.resolution)))
    _, first = np.unique(np.stack([r // k, c // k], axis=1), axis=0, return_index=True)
    r, c = r[first], c[first]
    return grid.origin + (np.stack([c, r], axis=1) + 0.5) * grid.resolution


def near_any(points, centres, radius: float) -> np.ndarray:
    """Per point (m, 2): whether some centre (k, 2) lies within ``radius``."""
    from scipy.spatial import cKDTree

    points = np.atleast_2d(np.asarray(points, dtype=float))
    centres = np.asarray(centres, dtype=float).reshape(-1, 2)
    if centres.shape[0] == 0 or points.shape[0] == 0:
        return np.zeros(points.shape[0], dtype=bool)
    d, _ = cKDTree(centres).query(points, k=1, distance_upper_bound=radius * (1 + 1e-12))
    return np.isfinite(d)


def line_of_sight(grid: SensedGrid, a, b, grown: bool = False) -> np.ndarray:
    """(m, k) bool: the straight segment from each point of ``a`` (m, 2) to each point of ``b``
    (k, 2) crosses no occupied cell (with ``grown``, no :func:`opaque` cell); unknown cells are
    transparent. The end cells themselves are not tested."""
    a = np.atleast_2d(np.asarray(a, dtype=float))
    b = np.atleast_2d(np.asarray(b, dtype=float))
    if a.shape[0] == 0 or b.shape[0] == 0:
        return np.zeros((a.shape[0], b.shape[0]), dtype=bool)
    length = float(np.hypot(*(a[:, None, :] - b[None, :, :]).transpose(2, 0, 1)).max())
    n = max(2, int(np.ceil(length / (grid.resolution / 2))))
    t = np.linspace(0.0, 1.0, n + 1)[1:-1]
    pts = a[:, None, None, :] + t[None, None, :, None] * (b[None, :, None, :] - a[:, None, None, :])
    rc = to_cells(grid, pts)
    H, W = grid.cells.shape
    inside = (rc[..., 0] >= 0) & (rc[..., 0] < H) & (rc[..., 1] >= 0) & (rc[..., 1] < W)
    wall = np.zeros(rc.shape[:-1], dtype=bool)
    block = opaque(grid) if grown else grid.cells == OCCUPIED
    wall[inside] = block[rc[..., 0][inside], rc[..., 1][inside]]
    return ~wall.any(axis=2)


def geodesic_labels(grid: SensedGrid, sources_xy, max_dist: float) -> tuple[np.ndarray, np.ndarray]:
    """Growth from ``sources_xy`` (m, 2) over sensed free cells that are not :func:`opaque`, up to
    ``max_dist``: per cell, the index of the source reached first (-1: none) and the path length
    (m; inf: not reached). Paths are 8-connected (diagonal steps sqrt(2) cells long, never
    cutting an impassable corner), so a length is at most 8 % above the straight line in open
    space, whatever the direction. Ties go to the lower source index."""
    H, W = grid.cells.shape
    full_label = np.full((H, W), -1, dtype=np.int64)
    full_dist = np.full((H, W), np.inf)
    src = to_cells(grid, np.atleast_2d(np.asarray(sources_xy, dtype=float)).reshape(-1, 2))
    ok = (src[:, 0] >= 0) & (src[:, 0] < H) & (src[:, 1] >= 0) & (src[:, 1] < W)
    if not ok.any():
        return full_label, full_dist
    # nothing farther than max_dist from a source is reached: work in that window only
    m = int(max_dist / grid.resolution) + 2
    r0, c0 = max(int(src[ok, 0].min()) - m, 0), max(int(src[ok, 1].min()) - m, 0)
    r1, c1 = min(int(src[ok, 0].max()) + m + 1, H), min(int(src[ok, 1].max()) + m + 1, W)
    passable = ((grid.cells == FREE) & ~opaque(grid))[r0:r1, c0:c1]
    src = src[ok] - np.array([r0, c0])
    src_idx = np.flatnonzero(ok)
    Hw, Ww = passable.shape
    passable[src[:, 0], src[:, 1]] = True  # a source is walkable even at the fringe of a wall
    # 8-connected graph of the window's passable cells; multi-source Dijkstra
    from scipy.sparse.csgraph import dijkstra

    from .grid_graph import grid_graph

    flat = np.arange(Hw * Ww).reshape(Hw, Ww)
    graph = grid_graph(passable)
    start = flat[src[:, 0], src[:, 1]]
    # the first source of each cell wins ties, as "lower index" (sources are visited in order)
    order = np.argsort(src_idx, kind="stable")
    steps, _, which = dijkstra(graph, directed=False, indices=start[order], min_only=True,
                               return_predecessors=True, limit=max_dist / grid.resolution + 1e-9)
    reached = np.isfinite(steps) & (which >= 0)
    label = np.full(Hw * Ww, -1, dtype=np.int64)
    pos = np.full(Hw * Ww, -1, dtype=np.int64)
    pos[start[order]] = src_idx[order]
    label[reached] = pos[which[reached]]
    dist = np.where(reached, steps * grid.resolution, np.inf)
    label, dist = label.reshape(Hw, Ww), dist.reshape(Hw, Ww)
    full_label[r0:r1, c0:c1] = label
    full_dist[r0:r1, c0:c1] = dist
    return full_label, full_dist


def path_lengths(grid: SensedGrid, source_xy) -> np.ndarray:
    """Per cell (the grid's shape), the length (m) of the shortest 8-connected path from
    ``source_xy`` over sensed free cells that are not :func:`opaque` (:func:`geodesic_labels`
    with one source and no length limit); inf where no such path exists."""
    H, W = grid.cells.shape
    return geodesic_labels(grid, np.asarray(source_xy, dtype=float).reshape(1, 2), (H + W) * grid.resolution)[1]


def lookup_near(grid: SensedGrid, values: np.ndarray, xy, cells: int = 2) -> np.ndarray:
    """The smallest of ``values`` (a per-cell array, e.g. :func:`path_lengths`) within ``cells``
    cells of each point of ``xy`` (n, 2): the way to the neighbourhood of a point that itself lies
    on a wall's fringe or on an unknown cell (a frontier point, a state beside furniture); inf
    outside the grid."""
    from scipy.ndimage import minimum_filter

    return lookup(grid, minimum_filter(values, size=2 * cells + 1, mode="constant", cval=np.inf), xy, np.inf)


def rank_viewpoints(gain, path, detour: float = 1.0, keep: int = -1, keep_ratio: float = 1.0) -> np.ndarray:
    """Viewpoints in order of information per metre, ``gain / (path + detour)`` (the oracle's
    rule), best first; viewpoints with no path (inf) or no gain are left out. The viewpoint
    ``keep`` (the one pursued so far) comes first while its score is at least ``keep_ratio``
    times the best, so the choice does not flip between near-equal viewpoints."""
    gain = np.asarray(gain, dtype=float)
    path = np.asarray(path, dtype=float)
    ok = np.isfinite(path) & (path >= 0) & (gain > 0)
    score = np.where(ok, gain / (np.where(ok, path, 0.0) + detour), -np.inf)
    order = np.argsort(-score, kind="stable")
    order = order[ok[order]]
    if order.size and 0 <= keep < score.size and ok[keep] and score[keep] >= keep_ratio * score[order[0]]:
        order = np.concatenate([[keep], order[order != keep]])
    return order


def state_toward(way_left, steps, step_length: float = 1.0, weight: float = 0.1) -> int:
    """The state from which the rest of the way to a viewpoint is shortest: the index minimising
    ``way_left + weight * steps * step_length`` (``way_left``: path length from each state to the
    viewpoint; ``steps``: believed-possible steps to reach the state, inf when none), so the
    nearest state to the viewpoint wins and the believed path breaks near-ties. -1 when no state
    has both."""
    steps = np.asarray(steps, dtype=float)
    finite = np.isfinite(steps)
    believed = weight * step_length * np.where(finite, steps, 0.0)
    cost = np.asarray(way_left, dtype=float) + np.where(finite, believed, np.inf)
    if cost.size == 0 or not np.isfinite(cost).any():
        return -1
    return int(np.argmin(cost))


def lookup(grid: SensedGrid, values: np.ndarray, xy, fill):
    """``values`` (a per-cell array of the grid's shape) at world points ``xy`` (n, 2); ``fill``
    outside the grid."""
    rc = to_cells(grid, np.atleast_2d(np.asarray(xy, dtype=float)))
    H, W = grid.cells.shape
    inside = (rc[:, 0] >= 0) & (rc[:, 0] < H) & (rc[:, 1] >= 0) & (rc[:, 1] < W)
    out = np.full(rc.shape[0], fill, dtype=values.dtype)
    out[inside] = values[rc[inside, 0], rc[inside, 1]]
    return out


def crossed_segments(points, a, b, tol: float = 0.1, margin: float = 0.15) -> np.ndarray:
    """Per segment ``a[i] -> b[i]`` ((m, 2) each): whether one of ``points`` (k, 2), e.g. the
    returns of the latest scan, lies within ``tol`` of it, between ``margin`` and ``1 - margin``
    of its length (so the end poses themselves are not tested)."""
    a = np.asarray(a, dtype=float).reshape(-1, 2)
    b = np.asarray(b, dtype=float).reshape(-1, 2)
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    if a.shape[0] == 0 or p.shape[0] == 0:
        return np.zeros(a.shape[0], dtype=bool)
    d = b - a
    L2 = np.maximum((d**2).sum(axis=1), 1e-12)
    t = ((p[None, :, :] - a[:, None, :]) * d[:, None, :]).sum(axis=2) / L2[:, None]  # (m, k)
    foot = a[:, None, :] + t[:, :, None] * d[:, None, :]
    near = ((p[None, :, :] - foot) ** 2).sum(axis=2) <= tol**2
    return (near & (t >= margin) & (t <= 1.0 - margin)).any(axis=1)

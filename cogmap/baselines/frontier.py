"""Frontier-based exploration (Yamauchi 1997) with the ROS ``explore_lite`` goal cost.

The robot builds its own occupancy grid in the **odometry frame** (so odometry drift bends
its map, as it would on a real robot) from the same LiDAR the other agents use:

* free: each scan filled as one polygon of its beam end points (``cv2.fillPoly``), exactly
  how coverage is measured; cells well inside the polygon also clear stale obstacle marks
  (a moved box disappears from the map);
* occupied: end points of beams that hit something (shorter than the maximum range), plus a
  bumper mark where a move was stopped by a collision (obstacles the LiDAR plane misses).

Frontiers are known-free cells 4-adjacent to unknown cells, grouped into 8-connected
clusters; clusters shorter than ``min_frontier_size`` are dropped. The goal is the cluster
minimising ``potential_scale * distance - gain_scale * size`` (explore_lite, with its
default scales 3 and 1; distance = straight-line distance from the robot to the nearest
frontier cell, size = cluster length in metres). The goal point is the cluster cell
reachable by the planner that is nearest the cluster centroid.

Paths are planned on the robot's map inflated by the robot radius plus a margin, on a 0.1 m
planning grid, **treating unknown cells as free** (Nav2's ``allow_unknown``): a frontier
lies by definition at the border of unknown space, and with the polygon fill the gaps
between grazing beams stay unknown although they are free; planning through unknown space
is safe here because a move stops before any collision, and the next scan corrects the
map. A goal is blacklisted (explore_lite's behaviour) when it is unreachable on the map,
when the path length to it has not shrunk for ``progress_timeout`` steps, after
``max_failures`` consecutive failed moves toward it, or when the robot stands on it and
the frontier persists. Exploration ends when no frontier is left.

Motion is the same as the agents': one ``move_to`` (odometry frame) of at most one step
length per decision, toward the farthest point of the planned path in straight-line sight.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from cogmap.envs.occupancy import OccupancyGrid

from .gridnav import coarsen, extract_path, inflate, line_free, next_waypoint, shortest_paths
from .policy import BaselinePolicy


@dataclass(frozen=True)
class FrontierConfig:
    """Settings of :class:`FrontierExplorer` (explore_lite's defaults where it has them).

    Attributes
    ----------
    resolution : float
        Map cell side, metres (default 0.05).
    plan_factor : int
        Planning grid cell = ``resolution * plan_factor`` (default 2).
    step_length : float
        Longest move per decision, metres.
    robot_radius : float
        Metres.
    inflation_margin : float
        Planned paths keep ``robot_radius + inflation_margin`` metres from obstacles.
    min_frontier_size : float
        Clusters shorter than this (metres) are dropped.
    potential_scale, gain_scale : float
        explore_lite's cost ``potential_scale * distance - gain_scale * size`` (defaults 3 and 1).
    progress_timeout : int
        Steps without getting closer before a goal is blacklisted.
    max_failures : int
        Consecutive failed moves before a goal is blacklisted.
    blacklist_radius : float
        Goals within this distance (metres) of a blacklisted one are skipped.
    goal_tolerance : float
        Distance (metres) at which the robot counts as on its goal.
    map_size : float
        Side (metres) of the square map centred on the start odometry.
    lidar_range : float
        Maximum LiDAR range, metres; shorter beams mark their end point occupied.
    """
    resolution: float = 0.05
    plan_factor: int = 2  # planning grid = resolution * plan_factor
    step_length: float = 1.0
    robot_radius: float = 0.22
    inflation_margin: float = 0.08  # planned paths keep radius + margin from obstacles
    min_frontier_size: float = 0.5  # m (explore_lite default 0.75 at 0.05 m cells)
    potential_scale: float = 3.0  # explore_lite defaults
    gain_scale: float = 1.0
    progress_timeout: int = 6  # steps without getting closer before a goal is blacklisted
    max_failures: int = 3  # consecutive failed moves before a goal is blacklisted
    blacklist_radius: float = 0.5
    goal_tolerance: float = 0.3
    map_size: float = 60.0  # side (m) of the square map centred on the start odometry
    lidar_range: float = 12.0


class OdomMap:
    """Occupancy grid in the odometry frame: ``seen`` (observed) and ``occ`` (occupied).

    Parameters
    ----------
    center_xy : array_like
        ``(x, y)`` centre of the square map, metres, odometry frame.
    size : float
        Side of the map, metres.
    resolution : float
        Cell side, metres.
    """

    def __init__(self, center_xy, size: float, resolution: float):
        n = int(np.ceil(size / resolution))
        self.resolution = resolution
        self.origin = (float(center_xy[0]) - n * resolution / 2, float(center_xy[1]) - n * resolution / 2)
        self.seen = np.zeros((n, n), bool)
        self.occ = np.zeros((n, n), bool)
        self._frame = OccupancyGrid(self.occ, self.origin, resolution)  # coordinate conversions
        self.bbox = None  # (r0, r1, c0, c1) of seen cells, inclusive-exclusive

    def to_cell(self, xy) -> np.ndarray:
        """Odometry-frame points to cells (the grid convention of the envs).

        Parameters
        ----------
        xy : array_like
            ``(..., 2)`` float, metres.

        Returns
        -------
        numpy.ndarray
            ``(..., 2)`` int ``(row, col)``.
        """
        return self._frame.world_to_cell(xy)

    def to_xy(self, rc) -> np.ndarray:
        """Cells to the odometry-frame coordinates of their centres.

        Parameters
        ----------
        rc : array_like
            ``(..., 2)`` cells, as :meth:`cogmap.envs.occupancy.OccupancyGrid.cell_to_world` takes them.

        Returns
        -------
        numpy.ndarray
            ``(..., 2)`` float, metres.
        """
        return self._frame.cell_to_world(rc)

    def _grow_bbox(self, r0, r1, c0, c1) -> None:
        if self.bbox is None:
            self.bbox = (r0, r1, c0, c1)
        else:
            b = self.bbox
            self.bbox = (min(b[0], r0), max(b[1], r1), min(b[2], c0), max(b[3], c1))

    def integrate(self, pose, ranges, angles, max_range: float) -> None:
        """Add one scan taken at odometry ``pose``.

        The polygon of beam end points becomes seen; end points of beams shorter than ``max_range``
        become occupied; cells deep inside the polygon clear stale obstacle marks.

        Parameters
        ----------
        pose : array_like
            ``(3,)`` odometry pose ``(x, y, yaw)``, metres and radians.
        ranges : array_like
            ``(B,)`` float beam ranges, metres.
        angles : array_like
            ``(B,)`` float beam angles in the robot frame, radians.
        max_range : float
            LiDAR maximum range, metres.
        """
        import cv2

        a = pose[2] + np.asarray(angles)
        r = np.asarray(ranges, float)
        pts = pose[:2] + r[:, None] * np.stack([np.cos(a), np.sin(a)], axis=1)
        cells = self.to_cell(pts)
        H, W = self.seen.shape
        r0, c0 = np.maximum(cells.min(axis=0) - 3, 0)
        r1, c1 = np.minimum(cells.max(axis=0) + 4, [H, W])
        if r1 <= r0 or c1 <= c0:
            return
        poly = np.round((pts - np.array(self.origin)) / self.resolution - 0.5).astype(np.int32)
        poly -= np.array([c0, r0], np.int32)
        win = np.zeros((r1 - r0, c1 - c0), np.uint8)
        cv2.fillPoly(win, [poly], 1)
        inside = win.astype(bool)
        hit = r < max_range - 1e-3
        hc = cells[hit]
        ok = (hc[:, 0] >= r0) & (hc[:, 0] < r1) & (hc[:, 1] >= c0) & (hc[:, 1] < c1)
        hc = hc[ok]
        hits = np.zeros_like(inside)
        hits[hc[:, 0] - r0, hc[:, 1] - c0] = True
        # cells deep inside this scan's free polygon are free now (clears moved obstacles)
        deep = ndimage.binary_erosion(inside, iterations=3) & ~ndimage.binary_dilation(hits, iterations=2)
        occ = self.occ[r0:r1, c0:c1]
        occ[deep] = False
        occ |= hits
        self.seen[r0:r1, c0:c1] |= inside | hits
        self._grow_bbox(int(r0), int(r1), int(c0), int(c1))

    def mark_occupied(self, xy, radius: float) -> None:
        """Mark a disc occupied (and seen), e.g. a bumper hit the LiDAR missed.

        Parameters
        ----------
        xy : array_like
            ``(x, y)`` centre, metres, odometry frame.
        radius : float
            Metres.
        """
        rc = self.to_cell(xy)
        k = int(np.ceil(radius / self.resolution))
        rr, cc = np.mgrid[-k:k + 1, -k:k + 1]
        disc = rr**2 + cc**2 <= k * k
        rows, cols = rc[0] + rr[disc], rc[1] + cc[disc]
        ok = (rows >= 0) & (rows < self.occ.shape[0]) & (cols >= 0) & (cols < self.occ.shape[1])
        self.occ[rows[ok], cols[ok]] = True
        self.seen[rows[ok], cols[ok]] = True


@dataclass
class Frontier:
    cells: np.ndarray  # (k, 2) map cells
    size_m: float
    centroid: np.ndarray  # odometry xy
    min_distance: float
    goal: np.ndarray | None
    path_m: float
    cost: float


@dataclass
class GoalTrack:
    """The frontier goal pursued and the progress toward it (explore_lite's blacklisting).

    Attributes
    ----------
    goal : numpy.ndarray or None
        ``(2,)`` goal, metres, odometry frame; None without one.
    best : float
        Best progress measure so far (path length or distance to the goal, metres).
    stuck : int
        Decisions without progress.
    failures : int
        Failed moves (or attempts) toward the goal.
    """

    goal: np.ndarray | None = None
    best: float = np.inf
    stuck: int = 0
    failures: int = 0


class FrontierExplorer(BaselinePolicy):
    """Greedy frontier exploration (Yamauchi 1997, explore_lite goal cost) on the robot's odometry-frame map.

    Uses only LiDAR and odometry; see the module docstring for the map, goal and blacklisting rules.

    Parameters
    ----------
    config : FrontierConfig, optional
        Settings; default ``FrontierConfig()``.
    """

    mode = "frontier"

    def __init__(self, config: FrontierConfig | None = None):
        self.cfg = config or FrontierConfig()
        self.map: OdomMap | None = None
        self.blacklist: list[np.ndarray] = []
        self.track = GoalTrack()
        self.last_heading: float | None = None
        self.frontiers: list[Frontier] = []
        self.done = False

    @property
    def goal(self) -> np.ndarray | None:
        """The frontier goal pursued (``(2,)`` metres, odometry frame), None without one."""
        return self.track.goal

    @property
    def blacklisted(self) -> int:
        """Number of goals blacklisted so far."""
        return len(self.blacklist)

    # ------------------------------------------------------------------ map
    def observe(self, odom, ranges, angles, moved: bool | None) -> None:
        """Update the map from one scan; a failed move adds a bumper mark ahead of the robot.

        Parameters
        ----------
        odom : numpy.ndarray or None
            ``(3,)`` odometry pose; nothing happens when None (dropped).
        ranges : numpy.ndarray or None
            Beam ranges, metres (None: LiDAR dropped).
        angles : numpy.ndarray
            Beam angles in the robot frame, radians.
        moved : bool or None
            Outcome of the last move.
        """
        cfg = self.cfg
        if odom is None:
            return
        if self.map is None:
            self.map = OdomMap(odom[:2], cfg.map_size, cfg.resolution)
        if moved is False and self.last_heading is not None:
            self.track.failures += 1
            h = self.last_heading
            bump = odom[:2] + (cfg.robot_radius + 0.05) * np.array([np.cos(h), np.sin(h)])
            self.map.mark_occupied(bump, 0.05)
        elif moved:
            self.track.failures = 0
        if ranges is not None:
            self.map.integrate(odom, ranges, angles, cfg.lidar_range)

    def _roi(self, margin_cells: int):
        r0, r1, c0, c1 = self.map.bbox
        H, W = self.map.seen.shape
        f = self.cfg.plan_factor
        r0, c0 = max(0, r0 - margin_cells), max(0, c0 - margin_cells)
        r1, c1 = min(H, r1 + margin_cells), min(W, c1 + margin_cells)
        r0, c0 = r0 - r0 % f, c0 - c0 % f  # align to the planning grid
        return r0, r1, c0, c1

    def detect(self, odom) -> list[Frontier]:
        """Frontier clusters with their goal, path length and explore_lite cost.

        Parameters
        ----------
        odom : array_like
            ``(>=2,)`` robot position in the odometry frame, metres.

        Returns
        -------
        list of Frontier
            Clusters of at least ``min_frontier_size``; ``goal`` is None for an unreachable one.
        """
        cfg, m = self.cfg, self.map
        res, f = cfg.resolution, cfg.plan_factor
        r0, r1, c0, c1 = self._roi(int(1.0 / res))
        seen, occ = m.seen[r0:r1, c0:c1], m.occ[r0:r1, c0:c1]
        free = seen & ~ndimage.binary_dilation(occ)
        unknown = ~seen
        frontier = free & ndimage.binary_dilation(unknown)  # 4-neighbourhood structuring element
        labels, n = ndimage.label(frontier, structure=np.ones((3, 3)))
        if n == 0:
            return []
        dist = self.plan_paths(odom, (r0, r1, c0, c1))
        robot = np.asarray(odom[:2], float)
        out = []
        idx = ndimage.find_objects(labels)
        for lab in range(1, n + 1):
            sl = idx[lab - 1]
            sub = labels[sl] == lab
            cells = np.argwhere(sub) + np.array([sl[0].start, sl[1].start])
            size_m = len(cells) * res
            if size_m < cfg.min_frontier_size:
                continue
            xy = m.to_xy(cells + np.array([r0, c0]))
            centroid = xy.mean(axis=0)
            min_d = float(np.min(np.hypot(*(xy - robot).T)))
            pd = dist[cells[:, 0] // f, cells[:, 1] // f] * res * f
            reach = np.isfinite(pd)
            goal, path_m = None, np.inf
            if reach.any():
                cand = np.flatnonzero(reach)
                j = cand[np.argmin(np.hypot(*(xy[cand] - centroid).T))]
                goal, path_m = xy[j], float(pd[j])
            cost = cfg.potential_scale * min_d - cfg.gain_scale * size_m
            out.append(Frontier(cells, size_m, centroid, min_d, goal, path_m, cost))
        return out

    def plan_paths(self, odom, roi, through_unknown: bool = True) -> np.ndarray:
        """Shortest paths from the robot over the map's inflated planning grid in ``roi``.

        Parameters
        ----------
        odom : array_like
            ``(>=2,)`` robot position in the odometry frame, metres.
        roi : tuple of int
            ``(r0, r1, c0, c1)`` map cells planned over (``r0``, ``c0`` aligned to the planning grid).
        through_unknown : bool, optional
            Plan through unseen cells (Nav2's ``allow_unknown``, the default); False keeps paths
            on seen cells.

        Returns
        -------
        numpy.ndarray
            Path length (planning cells) from the robot to every planning cell (inf: unreachable);
            the predecessors, blocked grid and offset are kept for :meth:`_waypoint`.
        """
        cfg, m = self.cfg, self.map
        res, f = cfg.resolution, cfg.plan_factor
        r0, r1, c0, c1 = roi
        blocked = inflate(m.occ[r0:r1, c0:c1], (cfg.robot_radius + cfg.inflation_margin) / res)
        if not through_unknown:
            blocked |= ~m.seen[r0:r1, c0:c1]
        blocked = coarsen(blocked, f)
        rc = m.to_cell(odom[:2]) - np.array([r0, c0])
        start = (int(np.clip(rc[0] // f, 0, blocked.shape[0] - 1)), int(np.clip(rc[1] // f, 0, blocked.shape[1] - 1)))
        if blocked[start]:  # squeezed against an obstacle (drift, bumper marks): let the robot leave
            k = int(np.ceil((cfg.robot_radius + cfg.inflation_margin) / (res * f)))
            blocked[max(0, start[0] - k):start[0] + k + 1, max(0, start[1] - k):start[1] + k + 1] = False
        dist, pred = shortest_paths(blocked, start)
        self._plan = (pred, blocked, (r0, c0), dist)  # dist: path length (planning cells) to every cell
        return dist

    def _blacklisted(self, xy) -> bool:
        return any(np.hypot(*(xy - b)) < self.cfg.blacklist_radius for b in self.blacklist)

    def _blacklist_goal(self) -> None:
        if self.track.goal is not None:
            self.blacklist.append(self.track.goal.copy())
        self.track = GoalTrack()

    # ------------------------------------------------------------------ decision
    def decide(self, odom) -> np.ndarray | None:
        """Next waypoint toward the cheapest non-blacklisted frontier, or None when exploration is finished.

        Parameters
        ----------
        odom : numpy.ndarray or None
            ``(3,)`` odometry pose.

        Returns
        -------
        numpy.ndarray or None
            ``(2,)`` float waypoint in the odometry frame, metres (the current position while no map
            exists yet); None when there is no odometry or no frontier is left.
        """
        cfg = self.cfg
        if odom is None or self.map is None or self.map.bbox is None:
            return None if odom is None else np.asarray(odom[:2], float)
        robot = np.asarray(odom[:2], float)
        for _ in range(50):  # re-select after blacklisting
            frontiers = self.detect(odom)
            self.frontiers = frontiers
            ok = [fr for fr in frontiers if fr.goal is not None and not self._blacklisted(fr.goal)]
            if not ok:
                self.done = True
                return None
            best = min(ok, key=lambda fr: fr.cost)
            if self.track.goal is None or np.hypot(*(best.goal - self.track.goal)) > cfg.blacklist_radius:
                self.track = GoalTrack(best.goal, best.path_m)
            else:
                self.track.goal = best.goal
                if best.path_m < self.track.best - 0.1:
                    self.track.best, self.track.stuck = best.path_m, 0
                else:
                    self.track.stuck += 1
            at_goal = np.hypot(*(robot - best.goal)) < cfg.goal_tolerance
            if self.track.stuck >= cfg.progress_timeout or self.track.failures >= cfg.max_failures or at_goal:
                self._blacklist_goal()
                continue
            return self._waypoint(robot, best.goal)
        self.done = True
        return None

    def _waypoint(self, robot, goal) -> np.ndarray:
        cfg, m = self.cfg, self.map
        pred, blocked, (r0, c0), _ = self._plan
        f = cfg.plan_factor
        g = m.to_cell(goal) - np.array([r0, c0])
        path = extract_path(pred, blocked.shape, (g[0] // f, g[1] // f))
        cells = np.asarray(path, float) * f + (f - 1) / 2 + np.array([r0, c0])
        pts = m.to_xy(cells)
        pts[0], pts[-1] = robot, goal

        def visible(p):
            a = (m.to_cell(robot) - np.array([r0, c0])) // f
            b = (m.to_cell(p) - np.array([r0, c0])) // f
            return line_free(blocked, a, b)

        wp = next_waypoint(pts, robot, cfg.step_length, visible)
        d = wp - robot
        self.last_heading = float(np.arctan2(d[1], d[0])) if np.hypot(*d) > 1e-6 else self.last_heading
        return wp

    # ------------------------------------------------------------------ policy interface
    def plan(self, sim, moved: bool | None):
        """Sense (LiDAR and odometry only), update the map, and choose the next waypoint.

        Parameters
        ----------
        sim : NavSim
            The simulator (read: odometry and LiDAR only).
        moved : bool or None
            Whether the last move succeeded (False: a collision stopped it); None before the first.

        Returns
        -------
        tuple or None
            ``(waypoint (2,), "odom")``, or None when exploration is finished.
        """
        odom = sim.odometry()
        self.observe(odom, sim.lidar(), sim.lidar_angles(), moved)
        wp = self.decide(odom)
        if wp is None:
            return None
        return wp, "odom"

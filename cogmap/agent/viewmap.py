"""What the agent's LiDAR has already sensed, in the belief frame, and what each state's view
would still reveal (the stateful side of ``cogmap.planning.sensed``)."""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from cogmap.inference.se2 import apply, rotate
from cogmap.planning import sensed as sg


@dataclass
class Pursuit:
    """The view-weighted target the planner pursues (:mod:`cogmap.agent.planner`).

    Attributes
    ----------
    target : int
        State pursued by the inductive term (kept while nearly the best), -1 for none.
    viewpoint : numpy.ndarray or None
        The viewpoint pursued (its state is ``target``).
    unreached : int
        States that promise information but no believed-possible path reaches.
    spent : list of (numpy.ndarray, float)
        ``(viewpoint, nearest state distance)`` set aside until a new state lies nearer.
    spent_at : int
        Number of states when ``spent`` was started.
    blind : bool
        The LiDAR is silent at this step: the map cannot grow, nothing is set aside.
    """

    target: int = -1
    viewpoint: np.ndarray | None = None
    unreached: int = 0
    spent: list = field(default_factory=list)
    spent_at: int = 0
    blind: bool = False


@lru_cache(maxsize=32)
def _full_area(radius: float, rays: int, resolution: float, free_path: bool) -> float:
    return sg.view_area(radius, rays, resolution, free_path=free_path)


class ViewMap:
    """Owns the sensed grid and a per-state cache of unseen view areas.

    Unseen areas only shrink as scans accumulate (cells go from unknown to free or occupied),
    so a state whose area fell below ``min_area`` is never queried again; each decision queries
    the states that still promise something and the new ones.
    """

    def __init__(self, cfg):
        self.cfg = cfg
        self.grid: sg.SensedGrid | None = None
        self.area = np.zeros(0)  # unseen area (m2) per state; NaN: not computed yet
        self.robot, self.returns = None, np.zeros((0, 2))  # the latest scan, belief frame
        self.frontier_cache: dict = {}  # frontier point -> unseen area, while nothing near it changes
        self._dirty_states = self._dirty_frontier = None  # box of cells changed since the last query
        self.doubt: set[int] = set()  # states beside a moved obstacle, preferred until visited
        self.pursuit = Pursuit()  # the view-weighted target the planner pursues

    @property
    def full(self) -> float:
        """Area (m2) of a view with nothing yet seen."""
        cfg = self.cfg
        return _full_area(cfg.view_radius, cfg.view_rays, cfg.view_resolution, cfg.view_free_path)

    def observe(self, frame, sensed) -> None:
        """Add the scan of ``sensed`` (points relative to the robot, odometry frame) to the grid,
        through the odometry -> belief transform ``frame`` (:class:`cogmap.inference.se2.SE2`)."""
        scan = sensed.scan
        if scan is None or sensed.odometry is None:
            return
        robot = apply(frame, np.asarray(sensed.odometry, dtype=float)[:2])

        def belief(rel):
            return robot + rotate(frame, np.asarray(rel, dtype=float).reshape(-1, 2))

        pts = belief(scan)
        if self.grid is None:
            self.grid = sg.empty(robot, self.cfg.view_resolution)
        if sensed.sweep is not None:  # the area the beams swept, as the coverage counts it
            ends = belief(sensed.sweep)
            before = sg.ensure(self.grid, np.vstack([robot[None, :], ends, pts]))
            self.grid = sg.mark_sweep(before, robot, ends, pts)
        else:  # returns only: the cells along their rays
            before = sg.ensure(self.grid, np.vstack([robot[None, :], pts]))
            self.grid = sg.mark_scan(before, robot, pts)
        self.robot, self.returns = robot, pts
        box = sg.changed_bounds(before, self.grid)  # views within reach of it must be recomputed
        self._dirty_states = sg.merge_boxes(self._dirty_states, box)
        self._dirty_frontier = sg.merge_boxes(self._dirty_frontier, box)

    def areas(self, poses: np.ndarray, visited: np.ndarray) -> np.ndarray | None:
        """Unseen view area (m2) of every state (``poses`` (n, 2)); None before any scan. A state
        the robot has stood on (``visited``) has been seen from: whatever its imagined view still
        misses is not visible from there (as for the oracle's viewpoints)."""
        if self.grid is None:
            return None
        n = len(poses)
        if self.area.size < n:
            self.area = np.concatenate([self.area, np.full(n - self.area.size, np.nan)])
        self.area[:n][np.asarray(visited[:n], dtype=bool)] = 0.0
        # recompute new states, and informative ones whose view reaches a cell that changed
        new = np.isnan(self.area[:n])
        live = (self.area[:n] >= self.cfg.view_min_area) & sg.box_within(poses, self._dirty_states,
                                                                           self.cfg.view_radius)
        self._dirty_states = None
        stale = np.flatnonzero(new | live)
        if stale.size:
            self.area[stale] = self._unseen(poses[stale])
        return self.area[:n]

    def doubtful(self, poses: np.ndarray, src: np.ndarray, dst: np.ndarray, state: int) -> np.ndarray:
        """States from which a transition believed possible (``src -> dst``), both ends within
        ``view_doubt_range`` of the robot, is crossed by a return of the latest scan (something
        now stands on it), that the robot sees (no return between it and the state: not a state
        behind or under the obstacle) and that still have another believed-possible transition:
        visiting them would update B_s there (parameter information gain). They stay preferred
        until the robot stands on them (``state``). Only nearby transitions are checked, where
        odometry drift has not moved the scan against the map."""
        self.doubt.discard(int(state))
        if self.robot is not None and src.size:
            d = np.hypot(*(poses - self.robot).T)
            near = (d[src] <= self.cfg.view_doubt_range) & (d[dst] <= self.cfg.view_doubt_range)
            if near.any():
                bad = np.zeros(src.size, dtype=bool)
                bad[near] = sg.crossed_segments(self.returns, poses[src[near]], poses[dst[near]])
                if bad.any():
                    sources = np.unique(src[bad])
                    sources = sources[np.isin(sources, np.unique(src[~bad])) & (sources != state)]
                    seen = ~sg.crossed_segments(self.returns, np.repeat(self.robot[None, :], sources.size, 0),
                                                poses[sources], tol=self.cfg.robot_radius, margin=0.0)
                    self.doubt.update(int(s) for s in sources[seen])
        return np.array(sorted(self.doubt), dtype=np.int64)

    def viewpoints(self, poses: np.ndarray, visited: np.ndarray,
                   areas: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Where a view would still reveal something, and how much (m2): the unvisited states
        whose own view would reveal at least ``view_min_area``, and the frontier points of the
        sensed grid (free cells beside unknown ones, one per ``view_frontier_spacing`` square)
        whose view would reveal ``view_frontier_area``, but not those within
        ``view_spent_radius`` of a visited state (what is left unseen there is not visible from
        close by). Returns the points (m, 2) and their unseen areas."""
        cfg = self.cfg
        visited = np.asarray(visited[: len(poses)], dtype=bool)
        states = np.flatnonzero((areas >= cfg.view_min_area) & ~visited)
        xy, gains = poses[states], areas[states]
        if self.grid is None:
            return xy, gains
        pts = sg.frontier_points(self.grid, cfg.view_frontier_spacing)
        pts = pts[~sg.near_any(pts, poses[visited], cfg.view_spent_radius)]
        if pts.shape[0] == 0:
            return xy, gains
        fa = self._frontier_areas(pts)
        keep = fa >= cfg.view_frontier_area
        return np.vstack([xy, pts[keep]]), np.concatenate([gains, fa[keep]])

    def _unseen(self, xy: np.ndarray) -> np.ndarray:
        cfg = self.cfg
        return sg.unseen_area(self.grid, xy, cfg.view_radius, cfg.view_rays, free_path=cfg.view_free_path,
                              bounds=cfg.view_bounds)

    def _frontier_areas(self, pts: np.ndarray) -> np.ndarray:
        """Unseen areas of frontier points, reusing those whose view no changed cell reaches."""
        cfg = self.cfg
        dirty = sg.box_within(np.asarray(list(self.frontier_cache) or np.zeros((0, 2))).reshape(-1, 2),
                              self._dirty_frontier, cfg.view_radius)
        for key, d in zip(list(self.frontier_cache), dirty, strict=True):
            if d:
                del self.frontier_cache[key]
        self._dirty_frontier = None
        keys = [(float(x), float(y)) for x, y in pts]
        self.frontier_cache = {k: self.frontier_cache[k] for k in keys if k in self.frontier_cache}
        todo = [i for i, k in enumerate(keys) if k not in self.frontier_cache]
        if todo:
            fresh = self._unseen(pts[todo])
            self.frontier_cache.update({keys[i]: float(a) for i, a in zip(todo, fresh, strict=True)})
        return np.array([self.frontier_cache[k] for k in keys])

    def fractions(self, areas: np.ndarray) -> np.ndarray:
        """Unseen fraction of each view, floored at ``view_floor`` (a state never promises
        nothing: the paper's information gain remains as a tie-break)."""
        return np.clip(areas / self.full, self.cfg.view_floor, 1.0)

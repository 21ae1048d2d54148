"""Oracle coverage tour on the known map, standing in for the paper's human teleoperation.

The operator knows the layout (ground-truth occupancy grid) and where the robot is (true
pose). Candidate viewpoints lie on a lattice over the cells a disc robot can reach; each
viewpoint's visible area is precomputed by casting rays on the true grid and filling the
polygon of their end points (the coverage rule). At each choice the oracle goes to the
viewpoint with the most still-unseen free area per metre of path (``gain / (path + 1 m)``),
among viewpoints that would add at least ``min_gain`` m2; seen cells are the robot's actual
LiDAR coverage. It moves along the shortest path on the inflated true grid, one
step-length ``move_to`` (world frame) per decision, and stops when nothing worth a detour
remains.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cogmap.metrics import scan_mask

from .gridnav import coarsen, extract_path, inflate, line_free, next_waypoint, shortest_paths
from .policy import BaselinePolicy


@dataclass(frozen=True)
class OracleConfig:
    """Settings of :class:`OracleTour`.

    Attributes
    ----------
    step_length : float
        Longest move per decision, metres.
    robot_radius : float
        Metres.
    inflation_margin : float
        Paths keep ``robot_radius + inflation_margin`` metres from obstacles.
    plan_factor : int
        Planning grid cell = grid resolution * ``plan_factor``.
    viewpoint_spacing : float
        Spacing of the viewpoint lattice, metres.
    rays : int
        Rays cast per viewpoint.
    lidar_range : float
        Metres.
    min_gain : float
        Smallest unseen free area (square metres) worth a viewpoint.
    detour_offset : float
        Metres added to the path length in the score ``gain / (path + offset)``.
    """
    step_length: float = 1.0
    robot_radius: float = 0.22
    inflation_margin: float = 0.08
    plan_factor: int = 2
    viewpoint_spacing: float = 0.5
    rays: int = 180
    lidar_range: float = 12.0
    min_gain: float = 0.25  # m2 of unseen free area
    detour_offset: float = 1.0  # m added to the path length in gain / (path + offset)


def visible_mask(occupied: np.ndarray, origin, resolution: float, xy, rays: int, max_range: float) -> np.ndarray:
    """Cells inside the polygon of ray end points cast on ``occupied`` from ``xy``."""
    a = np.linspace(0.0, 2 * np.pi, rays, endpoint=False)
    r = np.arange(0.0, max_range, resolution / 2)
    pts = np.asarray(xy)[None, None, :] + r[None, :, None] * np.stack([np.cos(a), np.sin(a)], -1)[:, None, :]
    cols = np.floor((pts[..., 0] - origin[0]) / resolution).astype(int)
    rows = np.floor((pts[..., 1] - origin[1]) / resolution).astype(int)
    H, W = occupied.shape
    inside = (rows >= 0) & (rows < H) & (cols >= 0) & (cols < W)
    hit = ~inside
    hit[inside] = occupied[rows[inside], cols[inside]]
    hit[:, -1] = True
    first = np.argmax(hit, axis=1)
    end = pts[np.arange(rays), first]
    return scan_mask(occupied.shape, origin, resolution, end)


class OracleTour(BaselinePolicy):
    """Oracle coverage tour on the known map (stands in for the paper's human teleoperation).

    Knows the true grid and true pose; goes to the viewpoint with the most still-unseen free area per
    metre of path, one world-frame move per decision (see the module docstring).

    Parameters
    ----------
    config : OracleConfig, optional
        Settings; default ``OracleConfig()``.
    """
    mode = "oracle"

    def __init__(self, config: OracleConfig | None = None):
        self.cfg = config or OracleConfig()
        self.ready = False
        self.target: int | None = None
        self.path: np.ndarray | None = None
        self.visited: set[int] = set()  # viewpoints stood on: whatever they still miss is not visible

    def _prepare(self, sim) -> None:
        cfg, grid = self.cfg, sim.grid
        res, f = grid.resolution, cfg.plan_factor
        self.free = sim.grid.reachable(sim.true_pose()[:2])
        self.blocked = coarsen(inflate(grid.occupied, (cfg.robot_radius + cfg.inflation_margin) / res), f)
        start = tuple(grid.world_to_cell(sim.true_pose()[:2]) // f)
        dist, _ = shortest_paths(self.blocked, start)
        k = max(1, int(round(cfg.viewpoint_spacing / (res * f))))
        rr, cc = np.mgrid[0:self.blocked.shape[0]:k, 0:self.blocked.shape[1]:k]
        cand = np.stack([rr.ravel(), cc.ravel()], 1)
        cand = cand[np.isfinite(dist[cand[:, 0], cand[:, 1]])]
        self.vp_cells = cand
        self.vp_xy = grid.cell_to_world(cand * f + (f - 1) / 2)
        self.vp_visible = []
        for xy in self.vp_xy:
            m = visible_mask(grid.occupied, grid.origin, res, xy, cfg.rays, cfg.lidar_range) & self.free
            self.vp_visible.append(np.flatnonzero(m))
        self.ready = True

    def _seen(self, sim) -> np.ndarray:
        from cogmap.harness import coverage_tracker

        return coverage_tracker(sim).seen.ravel()

    def _choose(self, sim) -> bool:
        cfg, grid = self.cfg, sim.grid
        res, f = grid.resolution, cfg.plan_factor
        seen = self._seen(sim)
        gains = np.array([np.count_nonzero(~seen[v]) for v in self.vp_visible]) * res**2
        start = tuple(grid.world_to_cell(sim.true_pose()[:2]) // f)
        dist, pred = shortest_paths(self.blocked, start)
        d = dist[self.vp_cells[:, 0], self.vp_cells[:, 1]] * res * f
        ok = (gains >= cfg.min_gain) & np.isfinite(d)
        ok[list(self.visited)] = False
        if not ok.any():
            return False
        score = np.where(ok, gains / (d + cfg.detour_offset), -np.inf)
        j = int(np.argmax(score))
        path = extract_path(pred, self.blocked.shape, self.vp_cells[j])
        pts = grid.cell_to_world(np.asarray(path) * f + (f - 1) / 2)
        pts[0] = sim.true_pose()[:2]
        self.target, self.path = j, pts
        return True

    def plan(self, sim, moved: bool | None):
        """Next waypoint along the tour, using the true pose, the true grid and the coverage so far.

        Parameters
        ----------
        sim : NavSim
            The simulator.
        moved : bool or None
            Whether the last move succeeded; a failed move marks the current viewpoint as visited.

        Returns
        -------
        tuple or None
            ``(waypoint (2,) metres, "world")``, or None when nothing worth a detour remains.
        """
        cfg = self.cfg
        if not self.ready:
            self._prepare(sim)
        pos = sim.true_pose()[:2]
        seen = self._seen(sim)
        arrived = self.target is not None and np.hypot(*(pos - self.vp_xy[self.target])) < 0.1
        if arrived or (self.target is not None and moved is False):
            self.visited.add(self.target)
        if (self.target is None or arrived or moved is False
                or np.count_nonzero(~seen[self.vp_visible[self.target]]) * sim.grid.resolution**2 < cfg.min_gain):
            if not self._choose(sim):
                return None
        # drop the path points already passed
        d = np.hypot(*(self.path - pos).T)
        i = int(np.argmin(d))
        self.path = self.path[i:]
        self.path[0] = pos
        f, grid = cfg.plan_factor, sim.grid

        def visible(p):
            a = grid.world_to_cell(pos) // f
            b = grid.world_to_cell(p) // f
            return line_free(self.blocked, a, b)

        return next_waypoint(self.path, pos, cfg.step_length, visible), "world"

    def believed_pose(self, sim) -> np.ndarray:  # the true position, world frame: the oracle knows it
        return sim.true_pose()[:2]

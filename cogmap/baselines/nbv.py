"""Next-best-view exploration: the oracle's decision rule on the robot's own map.

The oracle tour (:mod:`cogmap.baselines.oracle`) knows the true map; this explorer uses only what
its LiDAR has swept, with the same map as the frontier explorer (:class:`frontier.OdomMap`:
scan polygons seen, returns occupied, in the odometry frame). It answers one question for the
exploration studies: how much of the oracle's coverage efficiency comes from knowing the map,
and how much from its greedy choice of viewpoints?

* viewpoints: a lattice (``viewpoint_spacing``) over the seen cells the robot can reach on its
  inflated map;
* gain of a viewpoint: the unseen area a scan from there would sweep, casting ``rays`` rays of
  the LiDAR's range through the map; occupied cells stop a ray, and what lies behind ``u``
  metres of unseen cells counts with weight ``exp(-u / free_path)`` (the robot cannot know what
  hides in unseen space: a prior of independently occupied cells, mean free path 4 m);
* choice: the most gain per metre of path, ``gain / (path + detour_offset)``, among viewpoints
  worth at least ``min_gain`` (the oracle's rule), re-chosen at every decision;
* motion: one step along the shortest path over seen cells, as the frontier explorer moves.

Exploration ends when no reachable viewpoint is worth ``min_gain``. A viewpoint's gain never
grows (unseen cells only become seen, occupied ones stay occupied), so one found below
``min_gain`` is never cast again.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cogmap.planning.sensed import check_bounds, inside_bounds, ray_offsets

from .frontier import FrontierConfig, FrontierExplorer
from .gridnav import coarsen


@dataclass(frozen=True)
class NBVConfig(FrontierConfig):
    """Settings of :class:`NextBestView`: the frontier explorer's map and motion settings, plus
    the oracle's viewpoint rule.

    Attributes
    ----------
    viewpoint_spacing : float
        Spacing of the viewpoint lattice, metres (the oracle's).
    rays : int
        Rays cast per viewpoint.
    min_gain : float
        Smallest unseen area (square metres) worth a viewpoint.
    detour_offset : float
        Metres added to the path length in the score ``gain / (path + offset)``.
    free_path : float
        Mean free path (metres) of a ray through unseen space in the gain (:func:`unseen_gains`).
    bounds : tuple of float or None
        ``(xmin, ymin, xmax, ymax)`` of the space in the odometry frame, when its outline is known:
        the map counts every cell beyond it occupied, so no ray sees past it. None (default): the
        outline is learnt from the LiDAR.
    """
    viewpoint_spacing: float = 0.5
    rays: int = 72
    min_gain: float = 0.25
    detour_offset: float = 1.0
    free_path: float = 4.0
    bounds: tuple[float, float, float, float] | None = None

    def __post_init__(self):
        if self.bounds is not None:
            object.__setattr__(self, "bounds", check_bounds(self.bounds, "NBVConfig.bounds"))


def unseen_gains(seen: np.ndarray, occ: np.ndarray, resolution: float, cells: np.ndarray, rays: int,
                 max_range: float, free_path: float = np.inf) -> np.ndarray:
    """Unseen area (m2) each viewpoint's scan would sweep on a map.

    Parameters
    ----------
    seen, occ : numpy.ndarray
        ``(H, W)`` bool: cells the robot has swept, and cells it found occupied.
    resolution : float
        Cell side, metres.
    cells : numpy.ndarray
        ``(N, 2)`` int ``(row, col)`` viewpoint cells.
    rays : int
        Rays per viewpoint, evenly spread over the circle.
    max_range : float
        Ray length, metres.
    free_path : float, optional
        Mean free path (metres) of a ray through unseen space: a sample behind ``u`` metres of
        unseen cells counts with weight ``exp(-u / free_path)``, the chance that nothing unseen
        hides it (unseen cells independently occupied); default inf (unseen space is clear).

    Returns
    -------
    numpy.ndarray
        ``(N,)`` float: the area of the samples along the rays (each the annular wedge around it,
        :func:`cogmap.planning.sensed.ray_offsets`, so an open unseen plane gives the disc's
        area) that lie on unseen cells before the ray meets an occupied cell; rays stop at the
        map's edge.
    """
    cells = np.asarray(cells, dtype=np.int64).reshape(-1, 2)
    if cells.shape[0] == 0:
        return np.zeros(0)
    H, W = seen.shape
    off, w = ray_offsets(max_range, rays, resolution)  # (rays, samples, 2) metres as (x, y); (samples,) m2
    dc, dr = off[..., 0] / resolution, off[..., 1] / resolution
    out = np.zeros(cells.shape[0])
    for i, (r0, c0) in enumerate(cells):
        rr = np.floor(r0 + 0.5 + dr).astype(np.int64)
        cc = np.floor(c0 + 0.5 + dc).astype(np.int64)
        inside = (rr >= 0) & (rr < H) & (cc >= 0) & (cc < W)
        rr_c, cc_c = np.clip(rr, 0, H - 1), np.clip(cc, 0, W - 1)
        stop = ~inside | occ[rr_c, cc_c]
        before = np.cumsum(stop, axis=1) == 0  # neither an occupied cell nor the edge yet on this ray
        unseen = before & ~seen[rr_c, cc_c]
        if np.isfinite(free_path):
            hidden = np.cumsum(unseen, axis=1) * resolution  # unseen metres up to each sample
            out[i] = float((unseen * np.exp(-hidden / free_path) * w).sum())
        else:
            out[i] = float((unseen * w).sum())
    return out


class NextBestView(FrontierExplorer):
    """Greedy next-best-view exploration on the robot's own odometry-frame map (see the module
    docstring): the oracle's rule, without the oracle's map.

    Parameters
    ----------
    config : NBVConfig, optional
        Settings; default ``NBVConfig()``.
    """

    mode = "nbv"

    def __init__(self, config: NBVConfig | None = None):
        super().__init__(config or NBVConfig())
        self.dead: set[tuple[int, int]] = set()  # viewpoints found below min_gain (never worth it again)
        self.target: np.ndarray | None = None

    def decide(self, odom) -> np.ndarray | None:
        """Next waypoint toward the viewpoint with the most unseen area per metre of path, or None
        when no reachable viewpoint is worth ``min_gain``.

        Parameters
        ----------
        odom
            As in :meth:`FrontierExplorer.decide`.

        Returns
        -------
        numpy.ndarray or None
            The waypoint as in :meth:`FrontierExplorer.decide`; None also when nothing is left
            worth a detour.
        """
        cfg = self.cfg
        if odom is None or self.map is None or self.map.bbox is None:
            return None if odom is None else np.asarray(odom[:2], float)
        m, f, res = self.map, cfg.plan_factor, cfg.resolution
        # plan over the swept part of the map and a LiDAR range around it, so every ray stays inside
        r0, r1, c0, c1 = self._roi(int(np.ceil(cfg.lidar_range / res)) + f)
        dist = self.plan_paths(odom, (r0, r1, c0, c1), through_unknown=False)
        shape = dist.shape
        window = (slice(r0, r0 + shape[0] * f), slice(c0, c0 + shape[1] * f))
        unseen = coarsen(~m.seen[window], f)  # a planning cell is unseen while any of its cells is
        occ = coarsen(m.occ[window], f)  # and occupied when any is (walls stay closed)
        if cfg.bounds is not None:  # a known outline: beyond it is wall
            rc = np.stack(np.mgrid[0:shape[0], 0:shape[1]], -1) * f + (f - 1) / 2 + np.array([r0, c0])
            occ |= ~inside_bounds(m.to_xy(rc), cfg.bounds)
        k = max(1, int(round(cfg.viewpoint_spacing / (res * f))))
        rr, cc = np.nonzero(np.isfinite(dist) & ~unseen & ~occ)
        on = ((rr + r0 // f) % k == 0) & ((cc + c0 // f) % k == 0)  # a lattice fixed in the map
        rr, cc = rr[on], cc[on]
        keys = list(zip((rr + r0 // f).tolist(), (cc + c0 // f).tolist(), strict=True))
        alive = np.array([key not in self.dead for key in keys], dtype=bool)
        rr, cc = rr[alive], cc[alive]
        keys = [key for key, a in zip(keys, alive, strict=True) if a]
        gains = unseen_gains(~unseen, occ, res * f, np.stack([rr, cc], 1), cfg.rays, cfg.lidar_range,
                             cfg.free_path)
        worth = gains >= cfg.min_gain
        self.dead.update(key for key, w in zip(keys, worth, strict=True) if not w)
        if not worth.any():
            self.done = True
            return None
        score = np.where(worth, gains / (dist[rr, cc] * res * f + cfg.detour_offset), -np.inf)
        j = int(np.argmax(score))
        goal = m.to_xy(np.array([rr[j], cc[j]]) * f + (f - 1) / 2 + np.array([r0, c0]))
        self.target = goal
        robot = np.asarray(odom[:2], float)
        if np.hypot(*(goal - robot)) < cfg.goal_tolerance:
            self.dead.add(keys[j])  # standing on it: what it still misses is not visible from here
            return robot
        return self._waypoint(robot, goal)

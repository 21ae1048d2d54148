"""Frontier exploration as the paper ran it: ROS ``explore_lite`` sending frontier centroids to Nav2.

The paper's Frontiers baseline (section 4.1: "Frontier-based exploration using a 2D LiDAR and
Nav2 SLAM") "repeatedly attempts to reach unreachable frontier cells, wasting significant travel
distance" (section 4.2) and "often persisted in unreachable goals" (Appendix D.3). That comes from
how explore_lite chooses and sends goals, which this variant follows (our other variant,
:class:`~cogmap.baselines.frontier.FrontierExplorer`, sends the reachable frontier cell nearest
the centroid instead):

* the map, the frontier clusters and their cost are the same as
  :class:`~cogmap.baselines.frontier.FrontierExplorer` (odometry-frame occupancy grid,
  ``cost = potential_scale * min_distance - gain_scale * size``, explore_lite's scales 3 and 1),
  with explore_lite's ``min_frontier_size`` of 0.75 m;
* the goal is the cluster's **centroid**, whether or not it is reachable: it may lie in unknown
  space, behind a wall or inside an obstacle's inflation;
* navigation is Nav2-like: a shortest path on the map inflated by robot radius + margin, unknown
  cells allowed (NavFn ``allow_unknown``), to the goal or, when the goal cell is blocked or cut
  off, to the nearest reachable cell within ``planner_tolerance`` (NavFn's 0.5 m); the robot
  drives along it one step per decision, so a path through unknown space that is in fact blocked
  ends in a failed move (the simulator stops before contact), a bumper mark and a re-plan; at the
  end of a plan that stopped short of the goal the controller drives straight at the goal
  (Nav2's goal checker wants the goal itself), which fails when the goal is inside an obstacle;
* a failed attempt is a failed move toward the goal or a decision with no plan at all (Nav2's
  recovery behaviours, spin and wait, modelled as one decision in place); after
  ``max_failures`` failed attempts toward the same goal it is blacklisted (explore_lite
  blacklists a goal when Nav2 aborts it);
* progress (explore_lite's rule): the chosen frontier's distance to the robot must shrink; a goal
  that makes no progress for ``progress_timeout`` decisions (explore_lite's 30 s at the
  TurtleBot3's 0.26 m/s is about 8 m, 8 one-metre decisions) is blacklisted. A goal counts as the
  same while its centroid moves less than ``blacklist_radius`` (explore_lite's 5-cell
  tolerance at 0.05 m); a robot that reached the centroid while the frontier persists waits there
  until the timeout, as explore_lite does when it re-selects the same goal;
* blacklisted goals are skipped when their centroid lies within ``blacklist_radius`` of a
  blacklisted one; exploration ends when no frontier is left.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .frontier import FrontierConfig, FrontierExplorer, GoalTrack


@dataclass(frozen=True)
class FrontierPaperConfig(FrontierConfig):
    """Settings of :class:`FrontierPaperExplorer`: :class:`FrontierConfig` with explore_lite / Nav2 values.

    Attributes
    ----------
    min_frontier_size : float
        explore_lite's default, 0.75 m.
    progress_timeout : int
        Decisions without the frontier getting closer before blacklisting (explore_lite's 30 s), 8.
    max_failures : int
        Failed attempts (failed moves, no plan) before a goal is blacklisted, 3.
    blacklist_radius : float
        Metres; explore_lite's 5 cells of 0.05 m.
    goal_tolerance : float
        Nav2's ``xy_goal_tolerance``, metres.
    planner_tolerance : float
        NavFn's tolerance around a blocked goal, metres.
    """
    min_frontier_size: float = 0.75  # explore_lite default
    progress_timeout: int = 8  # decisions without the frontier getting closer (explore_lite 30 s)
    max_failures: int = 3  # failed attempts (failed moves, no plan) before a goal is blacklisted
    blacklist_radius: float = 0.25  # explore_lite: 5 cells of 0.05 m
    goal_tolerance: float = 0.25  # Nav2 xy_goal_tolerance
    planner_tolerance: float = 0.5  # NavFn tolerance around a blocked goal


class FrontierPaperExplorer(FrontierExplorer):
    """explore_lite-like frontier exploration: goals at frontier centroids, failures count.

    Parameters
    ----------
    config : FrontierPaperConfig, optional
        Settings; default ``FrontierPaperConfig()``.
    """

    mode = "frontier_paper"

    def __init__(self, config: FrontierPaperConfig | None = None):
        super().__init__(config or FrontierPaperConfig())
        # decisions without any plan to the goal, failed moves, decisions waiting at a reached goal
        # whose frontier persists, decisions driving straight at a goal the plan could not reach
        self.stats = {"plan_failures": 0, "failed_moves": 0, "waits": 0, "pushes": 0}

    def observe(self, odom, ranges, angles, moved: bool | None) -> None:
        """As the parent, but failures toward a goal accumulate (a successful move does not reset them).

        Parameters
        ----------
        odom : numpy.ndarray or None
            ``(3,)`` odometry pose.
        ranges : numpy.ndarray or None
            Beam ranges, metres.
        angles : numpy.ndarray
            Beam angles in the robot frame, radians.
        moved : bool or None
            Outcome of the last move.
        """
        before = self.track.failures
        super().observe(odom, ranges, angles, moved)
        if moved is False:
            self.stats["failed_moves"] += 1
        elif moved:
            self.track.failures = before

    def _reset_goal(self, goal) -> None:
        self.track = GoalTrack(None if goal is None else np.asarray(goal, float).copy())

    def _blacklist_goal(self) -> None:
        if self.track.goal is not None:
            self.blacklist.append(self.track.goal.copy())
        self._reset_goal(None)

    def plan_target(self, goal) -> tuple[np.ndarray, float] | None:
        """Where Nav2 would plan to, using the search from the last :meth:`detect`.

        The goal if its planning cell is reachable, else the reachable planning cell nearest the goal
        within ``planner_tolerance``.

        Parameters
        ----------
        goal : array_like
            ``(2,)`` goal in the odometry frame, metres.

        Returns
        -------
        tuple or None
            ``(target (2,) metres, path length in metres)``, or None when no plan exists.
        """
        cfg, m = self.cfg, self.map
        pred, blocked, (r0, c0), dist = self._plan
        f, res = cfg.plan_factor, cfg.resolution
        g = (m.to_cell(goal) - np.array([r0, c0])) // f
        H, W = blocked.shape
        if 0 <= g[0] < H and 0 <= g[1] < W and np.isfinite(dist[g[0], g[1]]):
            return np.asarray(goal, float), float(dist[g[0], g[1]] * res * f)
        k = int(np.ceil(cfg.planner_tolerance / (res * f)))
        rr, cc = np.mgrid[g[0] - k:g[0] + k + 1, g[1] - k:g[1] + k + 1]
        ok = (rr >= 0) & (rr < H) & (cc >= 0) & (cc < W)
        rr, cc = rr[ok], cc[ok]
        near = np.hypot(rr - g[0], cc - g[1]) * res * f <= cfg.planner_tolerance
        rr, cc = rr[near], cc[near]
        reach = np.isfinite(dist[rr, cc])
        if not reach.any():
            return None
        rr, cc = rr[reach], cc[reach]
        j = int(np.argmin(np.hypot(rr - g[0], cc - g[1])))
        cell = np.array([rr[j], cc[j]]) * f + (f - 1) / 2 + np.array([r0, c0])
        return m.to_xy(cell), float(dist[rr[j], cc[j]] * res * f)

    def decide(self, odom) -> np.ndarray | None:
        """Next waypoint toward the cheapest non-blacklisted frontier centroid.

        Parameters
        ----------
        odom
            As in :meth:`FrontierExplorer.decide`.

        Returns
        -------
        numpy.ndarray or None
            ``(2,)`` float waypoint in the odometry frame, metres (the robot's own position means wait in
            place); None when there is no odometry or exploration is finished.
        """
        cfg = self.cfg
        if odom is None or self.map is None or self.map.bbox is None:
            return None if odom is None else np.asarray(odom[:2], float)
        robot = np.asarray(odom[:2], float)
        for _ in range(50):  # re-select after blacklisting
            frontiers = self.detect(odom)
            self.frontiers = frontiers
            ok = [fr for fr in frontiers if not self._blacklisted(fr.centroid)]
            if not ok:
                self.done = True
                return None
            best = min(ok, key=lambda fr: fr.cost)
            if self.track.goal is None or np.hypot(*(best.centroid - self.track.goal)) > cfg.blacklist_radius:
                self._reset_goal(best.centroid)
            else:
                self.track.goal = best.centroid.copy()
            if best.min_distance < self.track.best - 1e-6:  # explore_lite's progress
                self.track.best, self.track.stuck = best.min_distance, 0
            else:
                self.track.stuck += 1
            if self.track.stuck >= cfg.progress_timeout or self.track.failures >= cfg.max_failures:
                self._blacklist_goal()
                continue
            target = self.plan_target(self.track.goal)
            if target is None:  # no plan: a failed attempt; Nav2 recovers in place
                self.track.failures += 1
                self.stats["plan_failures"] += 1
                if self.track.failures >= cfg.max_failures:
                    self._blacklist_goal()
                    continue
                return robot.copy()
            xy, _ = target
            if np.hypot(*(robot - xy)) >= cfg.goal_tolerance:
                return self._waypoint(robot, xy)
            to_goal = self.track.goal - robot
            gap = float(np.hypot(*to_goal))
            if gap < cfg.goal_tolerance:  # arrived; the frontier persists: wait (until the timeout)
                self.stats["waits"] += 1
                return robot.copy()
            # the plan ended short of a goal in an obstacle's inflation or cut off: the controller
            # still drives at the goal (a failed move when something is in the way)
            self.stats["pushes"] += 1
            step = min(cfg.step_length, gap)
            self.last_heading = float(np.arctan2(to_goal[1], to_goal[0]))
            return robot + step * to_goal / gap
        self.done = True
        return None

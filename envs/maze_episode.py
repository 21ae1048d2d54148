"""A LiDAR-maze exploration as the episode runner (:func:`cogmap.envs.episode.run`) drives it:
each control stepped in the simulator, its scan read, an online SLAM (if any) fed with the step and
the exploration curves recorded; and the record of such a run.

The exploration ratio is measured on the true positions over the Table II tiles
(:func:`cogmap.envs.maze.exploration_ratio`); the information gain is ``KL(q(M) || p(M))`` of the
SLAM's map (DVBF-LM paper, Appendix D).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cogmap.genmodel.contracts import Episode, EpisodePolicy

from .maze import Maze, exploration_ratio
from .maze_traversal import MazeRun


def _information(slam) -> float:
    """``KL(q(M) || p(M))`` of the SLAM's map, nats (jax is imported only when a run has a map)."""
    from cogmap.genmodel.latent_map import kl_map

    return float(kl_map(slam.params.q_map))


@dataclass
class ExploreResult:
    """One exploration run (what :func:`cogmap.dvbf.explore.explore` returns). Lengths are in maze
    units, angles in radians.

    Attributes
    ----------
    poses : numpy.ndarray, shape (T, 3)
        True poses (x, y, heading).
    controls : numpy.ndarray, shape (T - 1, 2)
        Commanded controls (turn, forward).
    scans : numpy.ndarray, shape (T, n_beams)
        LiDAR ranges per step.
    estimates : numpy.ndarray, shape (T, 3), or None
        The online SLAM's pose estimates (``mi`` or ``learn_map``), else None.
    ratio_curve : list of (int, float)
        ``(step, exploration ratio)`` over the Table II tiles.
    info_curve : list of (int, float)
        ``(step, KL(q(M) || p(M)))`` in nats (Appendix D); empty without a map.
    plan_seconds : list of float
        Wall-clock seconds of each planning call.
    blocked : int
        Steps on which a wall stopped the robot.
    pulled : int
        Planning calls that followed the frontier pull (``MIConfig.pull_below``).
    params : DVBFParams or None
        q(M) and emission at the end (``mi`` or ``learn_map``).
    model : DVBFConfig or None
        The model of ``params``.
    seconds : float
        Wall-clock seconds of the whole run.
    """

    poses: np.ndarray  # (T, 3) true poses
    controls: np.ndarray  # (T - 1, 2) commanded
    scans: np.ndarray  # (T, n_beams)
    estimates: np.ndarray | None  # (T, 3) the agent's pose estimates (mi / learn_map)
    ratio_curve: list  # [(step, exploration ratio)]
    info_curve: list  # [(step, KL(q(M) || p(M)))]
    plan_seconds: list  # wall clock of each planning call
    blocked: int
    pulled: int = 0
    params: object = None  # DVBF params at the end (mi / learn_map)
    model: object = None  # DVBFConfig
    seconds: float = 0.0

    def metrics(self, steps: int) -> dict:
        """The run's metrics (``metrics.json`` of ``cogmap dvbf explore``, one study run).

        Parameters
        ----------
        steps : int
            Time steps of the run; the final ratio is read at step ``steps - 1``.

        Returns
        -------
        dict
            ``ratio_final`` and ``ratio_curve`` (exploration ratio, Appendix D), ``info_gain_curve`` and
            ``info_gain_final`` (``KL(q(M) || p(M))`` in nats, None without a map), ``blocked_steps``,
            ``pulled_plans``, ``path_length`` (maze units), ``run_s``, ``plan_calls``,
            ``plan_call_median_s`` and ``plan_call_first_s`` (seconds, None without planning) and, with
            pose estimates, ``localisation_error_final`` / ``localisation_error_mean`` (maze units).
        """
        plan = np.array(self.plan_seconds) if self.plan_seconds else None
        out = {"ratio_final": ratio_at(self.ratio_curve, steps - 1), "ratio_curve": self.ratio_curve,
               "info_gain_curve": self.info_curve,
               "info_gain_final": self.info_curve[-1][1] if self.info_curve else None,
               "blocked_steps": self.blocked, "pulled_plans": self.pulled,
               "path_length": float(np.sum(np.hypot(*np.diff(self.poses[:, :2], axis=0).T))),
               "run_s": self.seconds, "plan_calls": len(self.plan_seconds),
               "plan_call_median_s": float(np.median(plan)) if plan is not None else None,
               "plan_call_first_s": float(plan[0]) if plan is not None else None}
        if self.estimates is not None:
            err = np.hypot(*(self.estimates[:, :2] - self.poses[:, :2]).T)
            out["localisation_error_final"] = float(err[-1])
            out["localisation_error_mean"] = float(err.mean())
        return out


class MazePilot(EpisodePolicy):
    """A maze explorer (:class:`cogmap.dvbf.explore.MIAgent`, :class:`~cogmap.planning.maze_explorers.RandomWalk` or
    :class:`~cogmap.planning.maze_explorers.Frontier`) as :func:`cogmap.envs.episode.run` calls
    it: it senses the pose, scan and bump of the last step and returns the next control.

    Parameters
    ----------
    policy : object
        Anything with ``act(pose, scan, blocked) -> control``.
    """

    label = "maze"

    def __init__(self, policy):
        self.policy = policy

    def sense(self, sim, outcome):
        return outcome

    def step(self, sensed) -> np.ndarray:
        pose, scan, blocked = sensed
        return self.policy.act(pose, scan, bool(blocked))


@dataclass
class MazeCurves:
    """The exploration curves of a maze run.

    Attributes
    ----------
    tiles : set of tuple
        The Table II tiles visited.
    ratio : list of (int, float)
        ``(step, exploration ratio)``.
    info : list of (int, float)
        ``(step, KL(q(M) || p(M)))`` in nats; empty without a map.
    """

    tiles: set
    ratio: list
    info: list


class MazeEpisode(Episode):
    """One maze exploration as :func:`cogmap.envs.episode.run` drives it: the run of
    :class:`~cogmap.envs.maze_traversal.MazeRun`, the online SLAM (if any) advanced on each step
    and the curves recorded.

    Parameters
    ----------
    sim : MazeSim
        The simulator, reset at ``start``.
    maze : Maze
        Its maze.
    curve_every : int
        Steps between two points of the curves.
    slam : object or None
        An online SLAM fed with every step (``advance(u, scan)``, ``flush()``, ``t`` and
        ``params.q_map``: :class:`cogmap.inference.online_slam.OnlineSLAM`), if any.
    steps : int
        Time steps of the run (the start counts as step 0).
    start : tuple
        ``(pose, scan)`` at the start.
    """

    def __init__(self, sim, maze: Maze, curve_every: int, slam, steps: int, start):
        self.sensors, self.maze, self.curve_every, self.slam, self.steps = sim, maze, curve_every, slam, steps
        pose, scan = start
        self.record = MazeRun(sim, pose, scan)
        self.curves = MazeCurves({tuple(r) for r in maze.tile_index(pose)}, [(0, exploration_ratio(maze, pose))], [])
        if slam is not None:
            self.curves.info.append((0, _information(slam)))

    def act(self, u):
        maze, every, slam, curves = self.maze, self.curve_every, self.slam, self.curves
        pose, scan, blocked = self.record.act(u)
        t = len(self.record.poses) - 1
        curves.tiles.add(tuple(maze.tile_index(pose)[0]))
        if slam is not None:
            # a bump sensor tells the agent that a wall stopped it: the filter then sees no translation
            # (the distance moved before the wall is not known to it)
            slam.advance(np.array([u[0], 0.0 if blocked else u[1]])[None], scan[None])
        if t % every == 0 or t == self.steps - 1:
            curves.ratio.append((t, len(curves.tiles) / maze.tiles**2))
            if slam is not None and slam.t == t and t % (10 * every) == 0:
                curves.info.append((t, _information(slam)))
        return pose, scan, blocked

    def end(self) -> None:
        if self.slam is not None:
            self.slam.flush()
            last = self.steps - 1
            if self.curves.info[-1][0] != last:
                self.curves.info.append((last, _information(self.slam)))


def ratio_at(curve, step: int) -> float:
    """The exploration ratio of a ``[(step, ratio)]`` curve at ``step`` (the last point at or before it).

    Parameters
    ----------
    curve : iterable of (int, float)
        ``(step, ratio)`` pairs in increasing step order.
    step : int
        The step to read.

    Returns
    -------
    float
        The ratio, 0.0 if no point is at or before ``step``.
    """
    best = 0.0
    for s, r in curve:
        if s <= step:
            best = r
    return best

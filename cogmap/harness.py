"""One episode loop for every exploration policy in a ``NavSim`` (AIMAPP and the baselines).

The harness owns what is not the policy's business: the episode record (trajectory rows,
coverage, distance, decision time), the LiDAR coverage of the run (ground truth, for the
metrics), acting on the simulator and the stopping rules. A policy follows :class:`Policy`
(:class:`cogmap.genmodel.contracts.EpisodePolicy`):

- ``sense(sim, moved)`` reads the sensors it is allowed (not timed; ``moved`` is the outcome of
  the last motion command, None before the first);
- ``step(sensed) -> Command`` decides (timed: ``decision_ms``); the command says where to go
  (or to stay, or that the policy has finished) and carries the policy's own trajectory fields.

:class:`cogmap.agent.policy.AgentPolicy` wraps the AIMAPP agent; the baselines
(:mod:`cogmap.baselines`) implement it through :class:`cogmap.baselines.policy.BaselinePolicy`.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from cogmap.genmodel.contracts import Episode as EpisodeContract
from cogmap.genmodel.contracts import EpisodePolicy as Policy
from cogmap.metrics import CoverageTracker


@dataclass
class Episode:
    """What a run produced (kept in memory; :func:`cogmap.explore.write_run` stores it).

    Every list has one entry per recorded step, and ``coverage`` and ``distance`` one more at the end
    (the state after the last motion).

    Attributes
    ----------
    rows : list of dict
        Trajectory rows: step, true and odometry pose (metres, radians), the policy's own fields,
        ``moved``, ``coverage``, ``distance`` and ``decision_ms``.
    coverage : list of float
        LiDAR coverage in [0, 1] of the reachable free area.
    distance : list of float
        Cumulative true distance driven, metres.
    decision_ms : list of float
        Wall-clock time of each decision, milliseconds.
    num_states : list of int
        Size of the policy's map at each step (0 when it reports none).
    """

    rows: list[dict] = field(default_factory=list)
    coverage: list[float] = field(default_factory=list)
    distance: list[float] = field(default_factory=list)
    decision_ms: list[float] = field(default_factory=list)
    num_states: list[int] = field(default_factory=list)


@dataclass
class Command:
    """A policy's decision at one step, as the harness executes and records it.

    Attributes
    ----------
    waypoint : numpy.ndarray or None
        ``(2,)`` float where to drive, metres, in ``frame``; None to stay in place.
    frame : str
        ``"odom"`` (default) or ``"world"``.
    row : dict
        The policy's own trajectory fields (believed pose, state, action, mode, ...; see
        :data:`cogmap.explore.TRAJ_FIELDS`).
    done : bool
        The policy has finished: the step is recorded, nothing is executed and the episode ends.
    status : dict
        Extra fields for the progress bar.
    decision : object
        The policy's own decision object, handed to ``on_step`` and ``stop``.
    """

    waypoint: np.ndarray | None
    frame: str = "odom"
    row: dict = field(default_factory=dict)
    done: bool = False
    status: dict = field(default_factory=dict)
    decision: Any = None


# The coverage of a simulator run is kept per simulator (runs that follow one another in one
# simulator, e.g. exploration then a goal, keep adding to it) without touching the simulator.
_TRACKERS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def coverage_tracker(sim) -> CoverageTracker:
    """The LiDAR coverage of this simulator run, created at the first call for ``sim``.

    Coverage is measured over the free area reachable from where the run began; later runs in the
    same simulator keep adding to it.

    Parameters
    ----------
    sim : NavSim
        The simulator.

    Returns
    -------
    CoverageTracker
    """
    tracker = _TRACKERS.get(sim)
    if tracker is None:
        free = sim.grid.reachable(sim.true_pose()[:2])
        tracker = _TRACKERS[sim] = CoverageTracker(free, sim.grid.origin, sim.grid.resolution)
    return tracker


def sweep(sim, tracker: CoverageTracker) -> None:
    """Add what the LiDAR sweeps now to the coverage (nothing while the LiDAR is silent).

    Parameters
    ----------
    sim : NavSim
        The simulator, whose LiDAR hits are read.
    tracker : CoverageTracker
        The run's coverage (:func:`coverage_tracker`).
    """
    if not sim.faults.dropped("lidar", sim.step_count):
        tracker.update(sim.lidar_hits()[0])


def execute(sim, command: Command) -> bool:
    """Drive (or stay) as commanded.

    Parameters
    ----------
    sim : NavSim
        The simulator that moves.
    command : Command
        The decision; ``waypoint`` None means stay.

    Returns
    -------
    bool
        Whether the motion succeeded (False when stopped before a collision).
    """
    if command.waypoint is None:
        return bool(sim.stay().success)
    return bool(sim.move_to(command.waypoint, frame=command.frame).success)


class RoomEpisode(EpisodeContract):
    """A room run as :func:`cogmap.envs.episode.run` drives it: LiDAR coverage, trajectory rows and
    the stopping rules of :func:`run_episode`.

    Parameters
    ----------
    sim : NavSim
        The simulator.
    ep : Episode
        The record to extend.
    dist : float
        Distance driven so far, metres.
    on_step, stop, stop_coverage, after_step, moved
        As in :func:`run_episode`.
    """

    def __init__(self, sim, ep: Episode, dist: float, on_step=None, stop=None, stop_coverage=None, after_step=None,
                 moved: bool | None = None):
        self.sensors, self.ep, self.dist, self.moved = sim, ep, dist, moved
        self.tracker = coverage_tracker(sim)
        self.on_step, self.stop_rule, self.stop_coverage, self.after_step = on_step, stop, stop_coverage, after_step
        self.last: Command | None = None

    def stop(self) -> str | None:
        sweep(self.sensors, self.tracker)
        if self.stop_coverage is not None and self.tracker.coverage >= self.stop_coverage:
            return "coverage"
        return None

    def decided(self, cmd: Command, ms: float) -> str | None:
        sim, ep, cov = self.sensors, self.ep, self.tracker.coverage
        true, odom = sim.true_pose(), sim.odometry()
        odom = np.full(3, np.nan) if odom is None else odom
        ep.coverage.append(cov)
        ep.distance.append(self.dist)
        ep.decision_ms.append(ms)
        ep.num_states.append(int(cmd.row.get("num_states", 0)))
        ep.rows.append(dict(
            step=len(ep.rows), true_x=true[0], true_y=true[1], true_yaw=true[2], odom_x=odom[0], odom_y=odom[1],
            odom_yaw=odom[2], **cmd.row, moved=self.moved, coverage=cov, distance=self.dist, decision_ms=ms,
        ))
        self.last = cmd
        if cmd.done:
            return "done"
        if self.on_step is not None:
            self.on_step(cmd.decision)
        return None

    def act(self, cmd: Command) -> bool:
        sim = self.sensors
        before = sim.true_pose()[:2]
        self.moved = execute(sim, cmd)
        self.dist += float(np.hypot(*(sim.true_pose()[:2] - before)))
        return self.moved

    def acted(self, cmd: Command, moved: bool) -> str | None:
        if self.stop_rule is not None and self.stop_rule(cmd.decision):
            return "stop"
        if self.after_step is not None:
            self.after_step(self.ep, moved, self.dist)
        return None

    def status(self) -> dict:
        return dict(cov=f"{self.tracker.coverage:.0%}", **(self.last.status if self.last is not None else {}))

    def end(self) -> None:
        sweep(self.sensors, self.tracker)
        self.ep.coverage.append(self.tracker.coverage)
        self.ep.distance.append(self.dist)


def run_episode(sim, policy: Policy, steps: int, *, progress: bool = False, episode: Episode | None = None,
                on_step=None, stop=None, stop_coverage: float | None = None, desc: str | None = None,
                after_step=None, moved: bool | None = None, distance: float | None = None) -> Episode:
    """Drive ``policy`` in ``sim`` for at most ``steps`` decisions, tracking LiDAR coverage.

    Ends early when the policy reports ``done``, when ``stop(decision)`` is true after a step was
    executed, or when the coverage reaches ``stop_coverage`` before a decision.

    Parameters
    ----------
    sim : NavSim
        The simulator.
    policy : Policy
        The exploration policy.
    steps : int
        Largest number of decisions.
    progress : bool, optional
        Show a tqdm progress bar, default False.
    episode : Episode, optional
        The episode of an earlier run to continue (rows, distance).
    on_step : callable, optional
        Called with ``command.decision`` before each executed step.
    stop : callable, optional
        ``stop(decision) -> bool`` checked after each executed step.
    stop_coverage : float, optional
        Coverage in [0, 1] at which to stop.
    desc : str, optional
        Progress-bar description; default ``policy.label``.
    after_step : callable, optional
        ``after_step(ep, moved, distance)`` runs at the end of every step that does not end the
        episode (where a checkpoint captures the whole loop state).
    moved : bool, optional
        Outcome of the last motion command, when resuming a loop from such a point.
    distance : float, optional
        Distance travelled so far (m), when resuming.

    Returns
    -------
    Episode
        The (new or continued) episode record.
    """
    from cogmap.envs.episode import run

    ep = episode if episode is not None else Episode()
    dist = distance if distance is not None else (ep.distance[-1] if ep.distance else 0.0)
    room = RoomEpisode(sim, ep, dist, on_step=on_step, stop=stop, stop_coverage=stop_coverage, after_step=after_step,
                       moved=moved)
    run(room, policy, steps, outcome=moved, progress=progress, desc=desc)
    return ep

"""One drone episode in the drone field: plan -> fly the first action -> replan (DRONE.md 2.7-2.8),
its stopping rules and metrics, driven by the episode runner (:func:`cogmap.envs.episode.run`).

Outcomes: success (final distance <= 1.5 m), stuck (over the last 15 s the drone never got more
than 1 m from where it was 15 s earlier), timeout (250 s simulated or 250 steps), crashed (a
collision with ``end_on_collision``). Each step costs its flight time plus ``step_overhead_s``
simulated seconds of hovering while the command is served (the original averaged 2.8 s per step for
about 1.6 s of flight).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np

from cogmap.genmodel.contracts import Episode, EpisodePolicy

SUCCESS_RADIUS = 1.5


@dataclass(frozen=True)
class EpisodeLimits:
    """Stopping rules and timing of one drone episode.

    Attributes
    ----------
    max_steps : int
        Decisions before a timeout, default 250.
    max_time_s : float
        Simulated seconds before a timeout, default 250.
    stuck_time_s : float
        Window (s) of the stuck test, default 15.
    stuck_distance : float
        The drone is stuck when it stayed within this many metres of where it was ``stuck_time_s``
        earlier, default 1.
    step_overhead_s : float
        Simulated seconds of hovering added per step while the command is served, default 1.
    success_radius : float
        Final distance (metres) to the target that counts as success, default 1.5.
    """
    max_steps: int = 250
    max_time_s: float = 250.0
    stuck_time_s: float = 15.0
    stuck_distance: float = 1.0
    step_overhead_s: float = 1.0
    success_radius: float = SUCCESS_RADIUS


def _stuck(times, positions, now: float, window: float, dist: float) -> bool:
    if now - times[0] < window:
        return False
    i = int(np.searchsorted(times, now - window, side="right")) - 1
    ref = positions[i]
    return bool((np.linalg.norm(np.asarray(positions[i:]) - ref, axis=1) < dist).all())


@dataclass
class DroneTrace:
    """What a drone episode writes down as it goes.

    Attributes
    ----------
    times, positions : list
        Simulated time (s) and position after each step, the start included (the stuck test).
    plan_ms, efe_us, rules : list
        Planning time (ms), EFE time per candidate (us) and the rule of each decision.
    replans : int
        In-flight replans.
    steps : int
        Steps flown.
    """

    times: list
    positions: list
    plan_ms: list = field(default_factory=list)
    efe_us: list = field(default_factory=list)
    rules: list = field(default_factory=list)
    replans: int = 0
    steps: int = 0


class DronePilot(EpisodePolicy):
    """A drone policy as :func:`cogmap.envs.episode.run` calls it: sense the LiDAR where the drone
    is, decide toward the target.

    Parameters
    ----------
    policy : DronePolicy
        The drone policy.
    target : numpy.ndarray
        ``(3,)`` target position, metres.
    """

    label = "drone"

    def __init__(self, policy, target):
        self.policy, self.target = policy, target

    def sense(self, sim, flight):
        pos = sim.position.copy()
        self.policy.observe(sim.scan(), pos)
        return pos

    def step(self, position):
        return self.policy.decide(position, self.target)


class DroneEpisode(Episode):
    """One drone flight as :func:`cogmap.envs.episode.run` drives it: the stopping rules of
    :class:`EpisodeLimits`, the flight of each first action (scans in flight go to the policy) and
    its trace.

    Parameters
    ----------
    sim : DroneSim
        The simulator (reset here).
    policy : DronePolicy
        The policy (reset here; in-flight scans and contacts go to it).
    target : numpy.ndarray
        ``(3,)`` target position, metres.
    limits : EpisodeLimits
        The stopping rules.
    log : callable, optional
        ``log(row)`` receives one dict per step.
    """

    def __init__(self, sim, policy, target, limits: EpisodeLimits, log=None):
        self.sensors, self.policy, self.target, self.limits, self.log = sim, policy, target, limits, log
        start = sim.reset()
        policy.reset(target, start)
        self.d0 = float(np.linalg.norm(target - start))
        replan = getattr(getattr(policy, "config", None), "replan_distance", None)
        self.replan_distance = replan if policy.replans_in_flight else None
        self.trace = DroneTrace([0.0], [start.copy()])

    def stop(self) -> str | None:
        sim, lim, tr = self.sensors, self.limits, self.trace
        if float(np.linalg.norm(self.target - sim.position)) <= lim.success_radius:
            return "success"
        if sim.crashed:
            return "crashed"
        if tr.steps >= lim.max_steps or sim.time >= lim.max_time_s:
            return "timeout"
        if _stuck(tr.times, tr.positions, sim.time, lim.stuck_time_s, lim.stuck_distance):
            return "stuck"
        return None

    def decided(self, dec, ms: float) -> None:
        self.trace.plan_ms.append(dec.plan_ms)
        self.trace.efe_us.append(dec.plan.efe_us_per_candidate)
        self.trace.rules.append(dec.plan.rule)

    def act(self, dec):
        sim, policy, tr = self.sensors, self.policy, self.trace
        pos = sim.position.copy()
        flight = sim.fly_to(dec.waypoint, dec.speed, replan_distance=self.replan_distance, on_scan=policy.observe)
        if flight.contact is not None:
            policy.observe_contact(flight.contact)
        sim.advance(self.limits.step_overhead_s)
        tr.steps += 1
        tr.replans += int(flight.replanned)
        tr.times.append(sim.time)
        tr.positions.append(sim.position.copy())
        if self.log is not None:
            self.log({"step": tr.steps, "time_s": round(sim.time, 3), "x": pos[0], "y": pos[1], "z": pos[2],
                      "wx": dec.waypoint[0], "wy": dec.waypoint[1], "wz": dec.waypoint[2],
                      "ex": sim.position[0], "ey": sim.position[1], "ez": sim.position[2],
                      "distance": float(np.linalg.norm(self.target - sim.position)), "collided": int(flight.collided),
                      "replanned": int(flight.replanned), "rule": dec.plan.rule, "plan_ms": round(dec.plan_ms, 4)})
        return flight

    def metrics(self, outcome: str) -> dict:
        """The episode's metrics (see :func:`fly_episode`)."""
        sim, tr, tgt = self.sensors, self.trace, self.target
        final = float(np.linalg.norm(tgt - sim.position))
        success = outcome == "success"
        pm = np.asarray(tr.plan_ms) if tr.plan_ms else np.zeros(1)
        eu = np.asarray([e for e in tr.efe_us if np.isfinite(e)])
        return {
            "outcome": outcome, "success": success, "stuck": outcome == "stuck", "timeout": outcome == "timeout",
            "crashed": outcome == "crashed", "collisions": int(sim.collisions),
            "collision_free_success": bool(success and sim.collisions == 0), "replans": tr.replans,
            "steps": tr.steps, "initial_distance": self.d0, "final_distance": final, "time_s": round(sim.time, 3),
            "fallback_steps": sum(r.startswith("fallback") for r in tr.rules),
            "plan_ms_median": float(np.median(pm)), "plan_ms_p95": float(np.percentile(pm, 95)),
            "efe_us_per_candidate_median": float(np.median(eu)) if len(eu) else None,
            "plan_ms": [round(float(x), 4) for x in tr.plan_ms],
            "target": [float(v) for v in tgt], "limits": asdict(self.limits),
        }


def fly_episode(sim, policy, target, limits: EpisodeLimits | None = None, log=None) -> dict:
    """Fly one episode from the simulator's start to ``target``: plan, fly the first action, replan.

    Parameters
    ----------
    sim : DroneSim
        The drone simulator (reset at the start).
    policy : DroneAgent or StraightLine or PotentialField
        Anything with ``reset``, ``observe``, ``observe_contact``, ``decide`` and ``replans_in_flight``.
    target : array_like
        ``(3,)`` target position, metres.
    limits : EpisodeLimits, optional
        Stopping rules; default ``EpisodeLimits()``.
    log : callable, optional
        ``log(row)`` receives one dict per step (step, time, position, waypoint, flags).

    Returns
    -------
    dict
        Metrics: ``outcome`` (``"success"``, ``"stuck"``, ``"timeout"`` or ``"crashed"``) and its
        flags, ``collisions``, ``collision_free_success``, ``replans``, ``steps``, initial and final
        distance (m), ``time_s``, ``fallback_steps``, planning times (ms: median, p95, every call), the
        median EFE time per candidate (us), ``target`` and ``limits``.
    """
    from cogmap.envs.episode import run

    tgt = np.asarray(target, float)
    episode = DroneEpisode(sim, policy, tgt, limits or EpisodeLimits(), log=log)
    return episode.metrics(run(episode, DronePilot(policy, tgt), None))


def summarise(episodes: list[dict]) -> dict:
    """Rates and means over episodes (replans split by success and failure; timing pooled over all planning calls).

    Parameters
    ----------
    episodes : list of dict
        Results of :func:`fly_episode`.

    Returns
    -------
    dict
        ``episodes`` (count), success / collision-free success / stuck / timeout / crashed rates,
        collisions per episode, episodes with a collision, mean replans on success and on failure,
        median and mean steps, mean final distance, planning-time median and p95 (ms) and median EFE
        time per candidate (us). Only ``{"episodes": 0}`` for an empty list.
    """
    n = len(episodes)
    if n == 0:
        return {"episodes": 0}
    ok = [e for e in episodes if e["success"]]
    bad = [e for e in episodes if not e["success"]]
    calls = np.concatenate([np.asarray(e["plan_ms"], float) for e in episodes if e["plan_ms"]] or [np.zeros(1)])
    eu = [e["efe_us_per_candidate_median"] for e in episodes if e.get("efe_us_per_candidate_median") is not None]

    def rate(key):
        return sum(bool(e[key]) for e in episodes) / n

    return {
        "episodes": n, "success_rate": rate("success"), "collision_free_success_rate": rate("collision_free_success"),
        "stuck_rate": rate("stuck"), "timeout_rate": rate("timeout"), "crashed_rate": rate("crashed"),
        "collisions_per_episode": float(np.mean([e["collisions"] for e in episodes])),
        "episodes_with_collision": sum(e["collisions"] > 0 for e in episodes),
        "replans_success_mean": float(np.mean([e["replans"] for e in ok])) if ok else None,
        "replans_failure_mean": float(np.mean([e["replans"] for e in bad])) if bad else None,
        "steps_median": float(np.median([e["steps"] for e in episodes])),
        "steps_mean": float(np.mean([e["steps"] for e in episodes])),
        "final_distance_mean": float(np.mean([e["final_distance"] for e in episodes])),
        "plan_ms_median": float(np.median(calls)), "plan_ms_p95": float(np.percentile(calls, 95)),
        "efe_us_per_candidate_median": float(np.median(eu)) if eu else None,
    }

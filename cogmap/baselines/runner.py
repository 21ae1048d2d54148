"""Drive a baseline policy in a ``NavSim`` and record the same :class:`cogmap.explore.Episode`
as an AIMAPP run (same rows, LiDAR coverage tracking, distance and timing), so
:func:`cogmap.explore.episode_metrics` applies unchanged.

A policy has ``step(sim, moved) -> (waypoint, frame) | None`` (None: it has finished) and
``believed_pose(sim) -> (x, y)``; it reads from ``sim`` only the sensors it is allowed
(documented per policy). One decision is one ``sim.move_to`` of at most one step length.
"""

from __future__ import annotations

import time

import numpy as np

from cogmap.explore import Episode, coverage_tracker


def run_policy(sim, policy, steps: int, progress: bool = False, stop_coverage: float | None = None,
               episode: Episode | None = None) -> Episode:
    """Run ``policy`` for at most ``steps`` decisions (fewer if it finishes or reaches
    ``stop_coverage``)."""
    from tqdm import tqdm

    ep = episode or Episode()
    tracker = coverage_tracker(sim)
    moved: bool | None = None
    dist = ep.distance[-1] if ep.distance else 0.0
    mode = getattr(policy, "mode", type(policy).__name__)
    bar = tqdm(range(steps), disable=not progress, desc=mode, unit="step", leave=True)
    for _ in bar:
        tracker.update(sim.lidar_hits()[0])
        if stop_coverage is not None and tracker.coverage >= stop_coverage:
            break
        t0 = time.perf_counter()
        cmd = policy.step(sim, moved)
        ms = 1e3 * (time.perf_counter() - t0)
        true, odom = sim.true_pose(), sim.odometry()
        odom = np.full(3, np.nan) if odom is None else odom
        belief = policy.believed_pose(sim)
        ep.coverage.append(tracker.coverage)
        ep.distance.append(dist)
        ep.decision_ms.append(ms)
        ep.num_states.append(0)
        ep.rows.append(dict(
            step=len(ep.rows), true_x=true[0], true_y=true[1], true_yaw=true[2], odom_x=odom[0], odom_y=odom[1],
            odom_yaw=odom[2], belief_x=belief[0], belief_y=belief[1], state=-1, action=-1,
            mode=mode if cmd is not None else "done", moved=moved, num_states=0, num_obs=0,
            coverage=tracker.coverage, distance=dist, decision_ms=ms,
        ))
        bar.set_postfix(cov=f"{tracker.coverage:.0%}")
        if cmd is None:
            break
        waypoint, frame = cmd
        before = sim.true_pose()[:2]
        moved = bool(sim.move_to(waypoint, frame=frame).success)
        dist += float(np.hypot(*(sim.true_pose()[:2] - before)))
    tracker.update(sim.lidar_hits()[0])
    ep.coverage.append(tracker.coverage)
    ep.distance.append(dist)
    return ep

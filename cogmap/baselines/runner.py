"""Drive a baseline policy in a ``NavSim`` and record the same :class:`cogmap.harness.Episode`
as an AIMAPP run (same harness: rows, LiDAR coverage tracking, distance and timing), so
:func:`cogmap.explore.episode_metrics` applies unchanged.

A baseline is a :class:`cogmap.baselines.policy.BaselinePolicy`: ``plan(sim, moved) ->
(waypoint, frame) | None`` (None: it has finished) and ``believed_pose(sim) -> (x, y)``; it
reads from ``sim`` only the sensors it is allowed (documented per policy).
"""

from __future__ import annotations

from cogmap.harness import Episode, coverage_tracker, run_episode

__all__ = ["coverage_tracker", "run_policy"]


def run_policy(sim, policy, steps: int, progress: bool = False, stop_coverage: float | None = None,
               episode: Episode | None = None) -> Episode:
    """Run a baseline for at most ``steps`` decisions (fewer if it finishes or reaches ``stop_coverage``).

    Parameters
    ----------
    sim : NavSim
        The simulator.
    policy : Policy
        The baseline (any :class:`cogmap.harness.Policy`).
    steps : int
        Largest number of decisions.
    progress : bool, optional
        Show a progress bar, default False.
    stop_coverage : float, optional
        Coverage in [0, 1] at which to stop.
    episode : Episode, optional
        An earlier episode to continue.

    Returns
    -------
    Episode
    """
    return run_episode(sim, policy, steps, progress=progress, episode=episode, stop_coverage=stop_coverage)

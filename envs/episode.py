"""The one episode runner of every system: sense, decide (timed), act, until a stopping rule.

The runner owns the loop, the timing of each decision and the progress bar. What differs between
the rooms, the drone field and the LiDAR mazes is split between two objects:

- the **policy** (:class:`cogmap.genmodel.contracts.EpisodePolicy`) says what it senses,
  ``policy.sense(world.sensors, outcome)`` (not timed), and decides, ``policy.step(sensed)``;
- the **episode** (:class:`cogmap.genmodel.contracts.Episode`) holds the simulator and the
  record of the run: its stopping rules, what it writes down of each decision and how an action
  is carried out.

The rooms' episode is :class:`cogmap.harness.RoomEpisode`, the drone's
:class:`cogmap.envs.drone_episode.DroneEpisode` and the mazes' :class:`cogmap.envs.maze_episode.MazeEpisode`.
"""

from __future__ import annotations

import itertools
import time

from cogmap.genmodel.contracts import Episode, EpisodePolicy


def run(episode: Episode, policy: EpisodePolicy, steps: int | None, *, outcome=None, progress: bool = False,
        desc: str | None = None) -> str:
    """Run ``policy`` in ``episode`` for at most ``steps`` decisions.

    Parameters
    ----------
    episode : Episode
        The run's simulator and record.
    policy : EpisodePolicy
        What senses and decides.
    steps : int or None
        Largest number of decisions; None for no limit (the episode's own rules stop it).
    outcome : object, optional
        The outcome the first ``sense`` receives (the last action's, when a run continues).
    progress : bool, optional
        Show a tqdm progress bar, default False.
    desc : str, optional
        Progress-bar description; default ``policy.label``.

    Returns
    -------
    str
        Why it ended: the reason the episode gave, or ``"steps"`` when the budget ran out.

    Raises
    ------
    ValueError
        If ``steps`` is negative.
    """
    from tqdm import tqdm

    if steps is not None and steps < 0:
        raise ValueError(f"run: steps must be >= 0 or None, got {steps}")
    bar = tqdm(range(steps) if steps is not None else itertools.count(), total=steps, disable=not progress,
               desc=desc or getattr(policy, "label", None), unit="step", leave=True)
    reason = "steps"
    for _ in bar:
        why = episode.stop()
        if why is not None:
            reason = why
            break
        sensed = policy.sense(episode.sensors, outcome)
        t0 = time.perf_counter()
        action = policy.step(sensed)
        why = episode.decided(action, 1e3 * (time.perf_counter() - t0))
        if progress:
            bar.set_postfix(episode.status())
        if why is not None:
            reason = why
            break
        outcome = episode.act(action)
        why = episode.acted(action, outcome)
        if why is not None:
            reason = why
            break
    bar.close()
    episode.end()
    return reason

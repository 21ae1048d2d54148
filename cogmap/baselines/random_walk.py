"""Random walk: a uniformly random heading each decision, one step length in the odometry frame.

Uses only odometry (the move is commanded relative to the believed pose, like every agent);
a move into an obstacle stops before the collision and counts as a failed move.
"""

from __future__ import annotations

import numpy as np

from .policy import BaselinePolicy


class RandomWalk(BaselinePolicy):
    """Random walk: a uniformly random heading each decision, one step length in the odometry frame.

    Parameters
    ----------
    step_length : float, optional
        Metres per move, default 1.
    seed : int, optional
        Seed of the heading draws, default 0.
    """
    mode = "random"

    def __init__(self, step_length: float = 1.0, seed: int = 0):
        self.step_length = float(step_length)
        self.rng = np.random.default_rng(seed)

    def plan(self, sim, moved: bool | None):
        """A waypoint one step length away along a random heading (relative to the odometry pose).

        Parameters
        ----------
        sim : NavSim
            The simulator (read: odometry only).
        moved : bool or None
            Outcome of the last move (unused).

        Returns
        -------
        tuple
            ``(waypoint (2,) metres, "odom")``; while odometry is dropped, the true position with
            ``"world"`` (the robot stays in place).
        """
        odom = sim.odometry()
        h = float(self.rng.uniform(0.0, 2 * np.pi))
        if odom is None:  # no odometry: move blind relative to the true pose cannot be commanded
            return sim.true_pose()[:2], "world"
        return odom[:2] + self.step_length * np.array([np.cos(h), np.sin(h)]), "odom"

"""The baselines as :class:`cogmap.harness.Policy`: a baseline reads from the simulator only the
sensors it is allowed (documented per baseline) when it decides, so what it "senses" is the
simulator itself with the outcome of the last move."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from cogmap.harness import Command


class SimView(NamedTuple):
    """A baseline's input at one step: the simulator and the outcome of the last move."""

    sim: object
    moved: bool | None


class BaselinePolicy:
    """Base of the baselines. A subclass implements ``plan(sim, moved) -> (waypoint, frame) | None``
    (None: it has finished) and ``believed_pose(sim) -> (x, y)``; one decision is one
    ``sim.move_to`` of at most one step length. ``mode`` names it in the trajectory."""

    mode = "baseline"

    @property
    def label(self) -> str:
        """Progress-bar description: the baseline's ``mode``."""
        return self.mode

    def sense(self, sim, moved: bool | None) -> SimView:
        """What the baseline senses: the simulator itself with the outcome of the last move.

        Parameters
        ----------
        sim : NavSim
            The simulator (each baseline reads only the sensors it is allowed).
        moved : bool or None
            Whether the last move succeeded; None before the first.

        Returns
        -------
        SimView
        """
        return SimView(sim, moved)

    def plan(self, sim, moved: bool | None):  # pragma: no cover - abstract
        """Choose the next waypoint (implemented by each baseline).

        Parameters
        ----------
        sim : NavSim
            The simulator.
        moved : bool or None
            Whether the last move succeeded; None before the first.

        Returns
        -------
        tuple or None
            ``(waypoint (2,) metres, frame)`` with frame ``"odom"`` or ``"world"``, or None when the
            baseline has finished.
        """
        raise NotImplementedError

    def believed_pose(self, sim) -> np.ndarray:
        """Where the baseline believes the robot is: its odometry position (the oracle overrides
        this with the true pose).

        Parameters
        ----------
        sim : NavSim
            The simulator (its odometry is read).

        Returns
        -------
        numpy.ndarray
            ``(2,)`` float, metres (nan while odometry is dropped).
        """
        odom = sim.odometry()
        return np.full(2, np.nan) if odom is None else odom[:2]

    def step(self, sensed: SimView) -> Command:
        """Plan and wrap the result as a harness command with the trajectory row.

        Parameters
        ----------
        sensed : SimView
            What :meth:`sense` returned.

        Returns
        -------
        Command
            ``done`` when :meth:`plan` returned None (mode ``"done"`` in the row).
        """
        cmd = self.plan(sensed.sim, sensed.moved)
        belief = self.believed_pose(sensed.sim)
        row = dict(belief_x=belief[0], belief_y=belief[1], state=-1, action=-1,
                   mode=self.mode if cmd is not None else "done", num_states=0, num_obs=0)
        if cmd is None:
            return Command(None, row=row, done=True)
        waypoint, frame = cmd
        return Command(waypoint, frame, row)

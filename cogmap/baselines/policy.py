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
        return self.mode

    def sense(self, sim, moved: bool | None) -> SimView:
        return SimView(sim, moved)

    def plan(self, sim, moved: bool | None):  # pragma: no cover - abstract
        raise NotImplementedError

    def believed_pose(self, sim) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def step(self, sensed: SimView) -> Command:
        cmd = self.plan(sensed.sim, sensed.moved)
        belief = self.believed_pose(sensed.sim)
        row = dict(belief_x=belief[0], belief_y=belief[1], state=-1, action=-1,
                   mode=self.mode if cmd is not None else "done", num_states=0, num_obs=0)
        if cmd is None:
            return Command(None, row=row, done=True)
        waypoint, frame = cmd
        return Command(waypoint, frame, row)

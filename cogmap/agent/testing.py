"""A small numpy world for agent tests and benchmarks (no simulator).

The robot moves in a rectangle with optional box obstacles. Observations name the cell of the
true position (``cell`` metres): every place looks different, as with a textured scene, and
places in the same cell look the same. Odometry may over-read distance (``slip``) and the robot
can be kidnapped; the obstacle signal checks the corridor of each heading against the walls
and boxes.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .aimapp import AIMAPPAgent, Decision, Sensed


class CellEncoder:
    """Observation id = the cell of the position it is given (ids in order of first sight)."""

    def __init__(self, cell: float = 0.5):
        self.cell = cell
        self.ids: dict[tuple[int, int], int] = {}
        self.last_scores = np.zeros(0)
        self.images: list[np.ndarray] = []  # it keeps no images (its "images" are positions)

    def _key(self, xy) -> tuple[int, int]:
        return int(np.floor(xy[0] / self.cell)), int(np.floor(xy[1] / self.cell))

    def match(self, xy) -> tuple[int, float]:
        """The id of the cell of ``xy`` with score 1, or (-1, 0.0) for a cell never seen."""
        i = self.ids.get(self._key(xy), -1)
        return i, float(i >= 0)

    def __call__(self, xy) -> tuple[int, bool]:
        key = self._key(xy)
        new = key not in self.ids
        if new:
            self.ids[key] = len(self.ids)
        self.last_scores = np.array([1.0])
        return self.ids[key], new


class BoxRoom(NamedTuple):
    """The static side of a :class:`BoxWorld`: its extent, boxes (visible and hidden), the robot's
    radius, step, headings and odometry slip."""

    size: np.ndarray
    boxes: list
    hidden: list  # block motion, unseen by the sensor
    radius: float
    step_length: float
    num_headings: int
    slip: float


class BoxWorld:
    """Rectangle ``[0, width] x [0, height]`` with axis-aligned boxes ``(x0, y0, x1, y1)``."""

    def __init__(self, width: float = 6.0, height: float = 6.0, boxes=(), start=(1.0, 1.0), slip: float = 0.0,
                 robot_radius: float = 0.22, step: float = 1.0, num_headings: int = 12, hidden=()):
        self.room = BoxRoom(np.array([width, height], dtype=float), [tuple(map(float, b)) for b in boxes],
                            [tuple(map(float, b)) for b in hidden], robot_radius, step, num_headings, slip)
        self.true = np.array(start, dtype=float)
        self.odom = self.true.copy()
        self.path = [self.true.copy()]
        self.dropped: set[int] = set()  # step numbers at which every sensor is silent
        self.steps = 0

    @property
    def boxes(self) -> list:
        """The visible boxes (a list: a test may add one)."""
        return self.room.boxes

    @property
    def size(self) -> np.ndarray:
        """``(width, height)``, metres."""
        return self.room.size

    def free(self, xy, boxes=None) -> bool:
        x, y = xy
        r = self.room.radius
        if not (r <= x <= self.size[0] - r and r <= y <= self.size[1] - r):
            return False
        boxes = self.boxes if boxes is None else boxes
        return not any(x0 - r < x < x1 + r and y0 - r < y < y1 + r for x0, y0, x1, y1 in boxes)

    def segment_free(self, a, b, n: int = 20, boxes=None) -> bool:
        return all(self.free(a + t * (b - a), boxes) for t in np.linspace(0.0, 1.0, n))

    def obstacles(self) -> np.ndarray:
        h = 2 * np.pi * np.arange(self.room.num_headings) / self.room.num_headings
        ends = self.true + self.room.step_length * np.stack([np.cos(h), np.sin(h)], axis=1)
        return np.array([not self.segment_free(self.true, e) for e in ends])

    def sense(self, moved: bool | None) -> Sensed:
        if self.steps in self.dropped:
            return Sensed(None, None, None, moved)
        return Sensed(self.true.copy(), self.obstacles(), np.r_[self.odom, 0.0], moved)

    def act(self, decision: Decision, stay: int) -> bool:
        """Drive toward the waypoint (odometry frame); stop before a collision."""
        self.steps += 1
        if decision.action == stay:
            return True
        delta = np.asarray(decision.waypoint, dtype=float) - self.odom
        target = self.true + delta
        ok = self.segment_free(self.true, target, boxes=self.room.boxes + self.room.hidden)
        if ok:
            self.true = target
            self.odom = self.odom + delta * (1.0 + self.room.slip)
        self.path.append(self.true.copy())
        return ok

    def odometry_jump(self, dxy) -> None:
        """A wheel-slip event: odometry moves by ``dxy`` while the robot does not."""
        self.odom = self.odom + np.asarray(dxy, dtype=float)

    def kidnap(self, xy) -> None:
        """Move the robot without telling odometry."""
        self.true = np.asarray(xy, dtype=float).copy()


def run(world: BoxWorld, agent: AIMAPPAgent, steps: int, moved: bool | None = None, on_step=None):
    """Drive ``agent`` in ``world``; returns the decisions and the last motion outcome."""
    decisions = []
    for _ in range(steps):
        d = agent.step(world.sense(moved))
        decisions.append(d)
        if on_step is not None:
            on_step(d)
        moved = world.act(d, agent.cfg.stay)
    return decisions, moved

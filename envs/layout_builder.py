"""What every room is made of: the :class:`Layout` record, the :class:`Builder` that collects
named shapes for it, and the wall constants (thickness, height, width of openings). The named
rooms (:mod:`.layouts`), the procedural buildings (:mod:`.buildings`) and building files
(:mod:`.layout_file`) all build on this module.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from .geometry import Box, Cylinder, Shape

WALL = 0.15
WALL_H = 2.0
OPENING = 1.6  # width of doorless openings between rooms: a 1 m lattice with 30-degree
# headings passes a 0.32 m corridor half-width through them off-centre
Pose = tuple[float, float, float]


@dataclass(frozen=True)
class Layout:
    """A room description independent of any physics engine.

    Attributes
    ----------
    name : str
        Layout name (also seeds the textures, see ``texture_name``).
    bounds : tuple of float
        ``(xmin, ymin, xmax, ymax)`` of the floor, metres, world frame.
    shapes : tuple of Shape
        Walls and furniture (``Box`` and ``Cylinder``), each with a unique name.
    starts : tuple of (float, float, float)
        Start poses ``(x, y, yaw)`` in metres and radians; seed ``k`` of a study starts at
        ``starts[k]`` while there are enough (``cogmap.starts.seed_start``).
    paper_area : float or None
        The free area (m2) the paper reports for this space, when it is one of the paper's.
    texture_seed : int or None
        Seeds the textures together with the name; None: the name alone.
    """

    name: str
    bounds: tuple[float, float, float, float]
    shapes: tuple[Shape, ...]
    starts: tuple[Pose, ...]
    paper_area: float | None = None
    texture_seed: int | None = None  # None: textures follow the name alone

    @property
    def texture_name(self) -> str:
        """What seeds the textures (see `textures`): the name, and the texture seed when given."""
        return self.name if self.texture_seed is None else f"{self.name}#{self.texture_seed}"

    def shape(self, name: str) -> Shape:
        """The shape called ``name``.

        Parameters
        ----------
        name : str
            A shape's name.

        Returns
        -------
        Shape
            That shape.

        Raises
        ------
        KeyError
            When the layout has no shape of that name.
        """
        for s in self.shapes:
            if s.name == name:
                return s
        raise KeyError(f"layout {self.name!r} has no shape named {name!r}")

    @property
    def names(self) -> list[str]:
        """Names of the shapes, in order."""
        return [s.name for s in self.shapes]

    def with_moved(self, name: str, xy, yaw: float | None = None) -> Layout:
        """A copy with shape ``name`` moved to ``xy`` (and turned to ``yaw`` for boxes).

        Parameters
        ----------
        name : str
            The shape to move.
        xy : array_like
            New centre ``(x, y)``, metres.
        yaw : float, optional
            New heading of a box, radians (ignored for cylinders).

        Returns
        -------
        Layout
            The moved copy (this layout is unchanged).
        """
        old = self.shape(name)
        kw = {"x": float(xy[0]), "y": float(xy[1])}
        if yaw is not None and isinstance(old, Box):
            kw["yaw"] = float(yaw)
        new = dataclasses.replace(old, **kw)
        return dataclasses.replace(
            self, shapes=tuple(new if s.name == name else s for s in self.shapes))


class Builder:
    """Collects shapes with unique names."""

    def __init__(self, seed: int):
        self.rng = np.random.default_rng(seed)
        self.shapes: list[Shape] = []
        self.counts: dict[str, int] = {}

    def _name(self, kind: str) -> str:
        k = self.counts.get(kind, 0)
        self.counts[kind] = k + 1
        return f"{kind}_{k:02d}"

    def box(self, kind, x, y, sx, sy, h=1.0, color=(0.6, 0.6, 0.6), yaw=0.0, movable=False,
            name=None):
        b = Box(name or self._name(kind), float(x), float(y), float(sx), float(sy), float(h),
                float(yaw), tuple(float(c) for c in color), movable)
        self.shapes.append(b)
        return b

    def cyl(self, kind, x, y, r, h=1.0, color=(0.5, 0.5, 0.5), movable=False, name=None):
        c = Cylinder(name or self._name(kind), float(x), float(y), float(r), float(h),
                     tuple(float(v) for v in color), movable)
        self.shapes.append(c)
        return c

    def hwall(self, y, x0, x1, gaps=(), t=WALL, color=(0.8, 0.8, 0.75)):
        """Horizontal wall along y from x0 to x1, leaving doorless openings (a, b)."""
        for a, b in wall_segments(x0, x1, gaps):
            self.box("wall", (a + b) / 2, y, b - a, t, WALL_H, color)

    def vwall(self, x, y0, y1, gaps=(), t=WALL, color=(0.8, 0.8, 0.75)):
        """Vertical wall along x from y0 to y1, leaving doorless openings (a, b)."""
        for a, b in wall_segments(y0, y1, gaps):
            self.box("wall", x, (a + b) / 2, t, b - a, WALL_H, color)

    def enclosure(self, w, h, colors):
        """Outer walls around the interior [0, w] x [0, h]; one colour per side (S, E, N, W)."""
        t = WALL
        self.box("wall", w / 2, -t / 2, w + 2 * t, t, WALL_H, colors[0])
        self.box("wall", w + t / 2, h / 2, t, h, WALL_H, colors[1])
        self.box("wall", w / 2, h + t / 2, w + 2 * t, t, WALL_H, colors[2])
        self.box("wall", -t / 2, h / 2, t, h, WALL_H, colors[3])
        return (-t, -t, w + t, h + t)

    def names(self):
        return [s.name for s in self.shapes]

    def jitter(self, s):
        return float(self.rng.uniform(-s, s))

    def color(self):
        return tuple(float(v) for v in self.rng.uniform(0.15, 0.95, 3))

    def layout(self, name, bounds, starts, paper_area=None) -> Layout:
        return Layout(name, tuple(float(b) for b in bounds), tuple(self.shapes),
                      tuple(tuple(float(v) for v in s) for s in starts), paper_area)


def wall_segments(a0, a1, gaps):
    """The stretches of ``[a0, a1]`` left by the openings ``gaps`` (pairs ``(start, end)``)."""
    segs, cur = [], a0
    for g0, g1 in sorted(gaps):
        if g0 > cur:
            segs.append((cur, g0))
        cur = max(cur, g1)
    if a1 > cur:
        segs.append((cur, a1))
    return segs

"""A seeded family of building-like layouts: corridors with side rooms, office floors, L, T and U
shaped corridors with rooms, and open halls with furniture.

Every building is drawn as a plan of labelled rectangles on a 0.1 m lattice (one label for the
corridor or hall, which may be L, T or U shaped, one per room). Walls follow every boundary between
two labels or between a label and the outside (so no wall is drawn twice); a room's wall to the
corridor gets a doorless opening of ``OPENING`` (1.6 m) metres, rooms do not open into each other.
Walls, furniture and textures come from the same primitives as the shipped layouts
(:class:`cogmap.envs.layout_builder.Builder`). Each layout is checked like a user's own building
(:func:`cogmap.envs.layout_file.check_layout`: one free region that holds every start, closed to
the outside) and carries at least :data:`MIN_STARTS` distinct start poses (corridor points and room
centres, at least 1 m apart).

    make_layout("building", seed=3, kind="office")    # or building(3, "office")

Free areas (m2, reachable from the first start): see :data:`AREA_RANGE`. All 300 buildings of
seeds 0-49 pass the checks.
"""

from __future__ import annotations

import numpy as np

from .layout_builder import OPENING, WALL, Builder, Layout

KINDS = ("corridor", "office", "L", "T", "U", "hall")
U = 0.1  # lattice step (m): every wall lies on a multiple of it
MIN_STARTS = 5
#: free area (m2) each kind stays within (checked by the tests); measured over seeds 0-49: corridor
#: 105-175, office 215-311, L 110-176, T 120-180, U 147-217, hall 117-235
AREA_RANGE = {"corridor": (90, 190), "office": (190, 330), "L": (95, 195), "T": (105, 200), "U": (130, 235),
              "hall": (100, 255)}
OUTER = (0.82, 0.82, 0.78)


class _Plan:
    """Labelled rectangles on the lattice: 0 = outside, 1 = corridor/hall, 2.. = rooms."""

    def __init__(self, rng: np.random.Generator):
        self.rng = rng
        self.rects: list[tuple[int, tuple[float, float, float, float]]] = []
        self.rooms: list[dict] = []  # label, rect, door side ("N", "S", "E", "W")

    def add(self, label: int, x0, y0, x1, y1) -> None:
        self.rects.append((label, (x0, y0, x1, y1)))

    def free(self, x0, y0, x1, y1) -> bool:
        """No existing rectangle overlaps this one (touching edges is fine)."""
        return all(x1 <= a0 + 1e-9 or x0 >= a1 - 1e-9 or y1 <= b0 + 1e-9 or y0 >= b1 - 1e-9
                   for _, (a0, b0, a1, b1) in self.rects)

    def room(self, x0, y0, x1, y1, door: str) -> bool:
        if not self.free(x0, y0, x1, y1):
            return False
        label = 2 + len(self.rooms)
        self.add(label, x0, y0, x1, y1)
        self.rooms.append({"label": label, "rect": (x0, y0, x1, y1), "door": door})
        return True

    def rooms_along(self, x0, x1, y, side: str, depth=(3.0, 4.5), width=(3.0, 4.6)) -> None:
        """Rooms side by side along a horizontal corridor edge at ``y`` (above it for side "N",
        below for "S"), from ``x0`` to ``x1``; doors face the corridor."""
        x = x0
        while x1 - x >= width[0]:
            w = min(_q(self.rng.uniform(*width)), _q(x1 - x))
            if x1 - x - w < width[0]:
                w = _q(x1 - x)  # no sliver left at the end
            d = _q(self.rng.uniform(*depth))
            rect = (x, y, x + w, y + d) if side == "N" else (x, y - d, x + w, y)
            self.room(*rect, door="S" if side == "N" else "N")
            x += w

    def rooms_beside(self, y0, y1, x, side: str, depth=(3.0, 4.5), width=(3.0, 4.6)) -> None:
        """Rooms along a vertical corridor edge at ``x`` (east of it for "E", west for "W")."""
        y = y0
        while y1 - y >= width[0]:
            w = min(_q(self.rng.uniform(*width)), _q(y1 - y))
            if y1 - y - w < width[0]:
                w = _q(y1 - y)
            d = _q(self.rng.uniform(*depth))
            rect = (x, y, x + d, y + w) if side == "E" else (x - d, y, x, y + w)
            self.room(*rect, door="W" if side == "E" else "E")
            y += w

    def grid(self) -> tuple[np.ndarray, float, float]:
        """Label grid (rows = y) on the lattice, with a ring of outside cells; and its origin."""
        xs = [v for _, r in self.rects for v in (r[0], r[2])]
        ys = [v for _, r in self.rects for v in (r[1], r[3])]
        ox, oy = min(xs) - U, min(ys) - U
        nx, ny = int(round((max(xs) - ox) / U)) + 1, int(round((max(ys) - oy) / U)) + 1
        g = np.zeros((ny, nx), dtype=int)
        for label, (x0, y0, x1, y1) in self.rects:
            c0, c1 = int(round((x0 - ox) / U)), int(round((x1 - ox) / U))
            r0, r1 = int(round((y0 - oy) / U)), int(round((y1 - oy) / U))
            g[r0:r1, c0:c1] = label
        return g, ox, oy


def _q(v: float) -> float:
    """Round to the lattice."""
    return round(v / U) * U


def _walls(b: Builder, plan: _Plan, colors: dict[int, tuple]) -> None:
    """Walls on every label boundary; a door where a room meets the corridor."""
    g, ox, oy = plan.grid()
    rng = plan.rng
    door_of = {r["label"]: r for r in plan.rooms}
    for axis in (0, 1):  # 0: horizontal walls (between rows), 1: vertical walls (between columns)
        a = g if axis == 0 else g.T
        for k in range(1, a.shape[0]):
            lo, hi = a[k - 1], a[k]
            j = 0
            n = a.shape[1]
            while j < n:
                if lo[j] == hi[j]:
                    j += 1
                    continue
                pair = (lo[j], hi[j])
                j0 = j
                while j < n and (lo[j], hi[j]) == pair:
                    j += 1
                start = (ox if axis == 0 else oy) + j0 * U
                end = (ox if axis == 0 else oy) + j * U
                line = (oy if axis == 0 else ox) + k * U
                gaps = []
                labels = set(pair)
                if 1 in labels and labels & set(door_of) and end - start >= OPENING + 0.8:
                    mid = _q(rng.uniform(start + OPENING / 2 + 0.4, end - OPENING / 2 - 0.4))
                    gaps = [(mid - OPENING / 2, mid + OPENING / 2)]
                room = max(pair)
                color = OUTER if 0 in labels else colors.get(room, OUTER)
                if axis == 0:
                    b.hwall(line, start - WALL / 2, end + WALL / 2, gaps, color=color)
                else:
                    b.vwall(line, start - WALL / 2, end + WALL / 2, gaps, color=color)


def _furnish_room(b: Builder, room: dict) -> None:
    """A desk or a cabinet against the wall opposite the door, a chair or a plant in a corner."""
    x0, y0, x1, y1 = room["rect"]
    rng = b.rng
    m = WALL / 2 + 0.05
    door = room["door"]
    kind = str(rng.choice(["desk", "cabinet", "bed", "shelf"]))
    size = {"desk": (1.2, 0.6, 0.75), "cabinet": (1.0, 0.5, 1.6), "bed": (1.8, 0.9, 0.5), "shelf": (1.4, 0.35, 1.8)}
    sx, sy, h = size[kind]
    color = b.color()
    if door in ("N", "S"):  # back wall is horizontal
        x = (x0 + x1) / 2 + b.jitter(max(0.0, (x1 - x0) / 2 - sx / 2 - 0.4))
        y = y0 + m + sy / 2 if door == "N" else y1 - m - sy / 2
        b.box(kind, x, y, sx, sy, h, color)
        cx = x0 + m + 0.3 if rng.random() < 0.5 else x1 - m - 0.3
        cy = y0 + m + 0.3 if door == "N" else y1 - m - 0.3
    else:
        y = (y0 + y1) / 2 + b.jitter(max(0.0, (y1 - y0) / 2 - sx / 2 - 0.4))
        x = x0 + m + sy / 2 if door == "E" else x1 - m - sy / 2
        b.box(kind, x, y, sy, sx, h, color)
        cy = y0 + m + 0.3 if rng.random() < 0.5 else y1 - m - 0.3
        cx = x0 + m + 0.3 if door == "E" else x1 - m - 0.3
    b.cyl("plant" if rng.random() < 0.5 else "chair", cx, cy, 0.22, 0.9, b.color())


def _corridor_points(rects, spacing: float = 3.0) -> list[tuple[float, float]]:
    """Points along the middle of each corridor rectangle."""
    pts = []
    for x0, y0, x1, y1 in rects:
        if x1 - x0 >= y1 - y0:
            n = max(1, int((x1 - x0) // spacing))
            pts += [(x0 + (i + 0.5) * (x1 - x0) / n, (y0 + y1) / 2) for i in range(n)]
        else:
            n = max(1, int((y1 - y0) // spacing))
            pts += [((x0 + x1) / 2, y0 + (i + 0.5) * (y1 - y0) / n) for i in range(n)]
    return pts


def _starts(rng, corridor_pts, rooms, hall_pts=()) -> list[tuple[float, float, float]]:
    """Corridor points first, then room centres, keeping only points >= 1 m apart."""
    centres = [((r["rect"][0] + r["rect"][2]) / 2, (r["rect"][1] + r["rect"][3]) / 2) for r in rooms]
    cand = list(corridor_pts) + list(hall_pts) + centres
    chosen: list[tuple[float, float]] = []
    for p in cand:
        if all(np.hypot(p[0] - q[0], p[1] - q[1]) >= 1.0 for q in chosen):
            chosen.append(p)
    headings = np.pi / 2 * rng.integers(0, 4, len(chosen))
    return [(float(x), float(y), float(h)) for (x, y), h in zip(chosen, headings, strict=True)]


def _corridor_shape(plan: _Plan, kind: str, rng) -> list[tuple[float, float, float, float]]:
    """The corridor's rectangles (label 1) for a kind; rooms are added along them by the caller."""
    w = _q(rng.uniform(1.8, 2.4))
    if kind == "corridor":
        length = _q(rng.uniform(14.0, 22.0))
        arms = [(0.0, 0.0, length, w)]
    elif kind == "L":
        a, c = _q(rng.uniform(10.0, 16.0)), _q(rng.uniform(8.0, 13.0))
        arms = [(0.0, 0.0, a, w), (a - w, w, a, c)]
    elif kind == "T":
        a, c = _q(rng.uniform(14.0, 20.0)), _q(rng.uniform(7.0, 11.0))
        sx = _q(a / 2 - w / 2 + rng.uniform(-2.0, 2.0))
        arms = [(0.0, 0.0, a, w), (sx, w, sx + w, w + c)]
    elif kind == "U":
        a, c = _q(rng.uniform(12.0, 17.0)), _q(rng.uniform(8.0, 11.0))
        arms = [(0.0, 0.0, a, w), (0.0, w, w, c), (a - w, w, a, c)]
    else:
        raise ValueError(f"unknown corridor kind {kind!r}")
    for r in arms:
        plan.add(1, *r)
    return arms


def _rooms_for(plan: _Plan, kind: str, arms) -> None:
    rng = plan.rng
    if kind == "corridor":
        (x0, y0, x1, y1), = arms
        dead_end = _q(rng.uniform(0.0, 3.0))  # a stretch of corridor without rooms
        plan.rooms_along(x0, x1 - dead_end, y1, "N")
        plan.rooms_along(x0 + dead_end, x1, y0, "S")
    elif kind == "L":
        (h0, hy0, h1, hy1), (vx0, vy0, vx1, vy1) = arms
        plan.rooms_along(h0, vx0, hy1, "N")  # inside the L
        plan.rooms_along(h0, h1, hy0, "S")
        plan.rooms_beside(vy0, vy1, vx1, "E")
    elif kind == "T":
        (h0, hy0, h1, hy1), (vx0, vy0, vx1, vy1) = arms
        plan.rooms_along(h0, vx0, hy1, "N")
        plan.rooms_along(vx1, h1, hy1, "N")
        plan.rooms_along(h0, h1, hy0, "S")
    elif kind == "U":
        (h0, hy0, h1, hy1), (lx0, ly0, lx1, ly1), (rx0, ry0, rx1, ry1) = arms
        plan.rooms_along(lx1, rx0, hy1, "N", depth=(3.0, min(4.5, ly1 - ly0)))  # inside the U
        plan.rooms_beside(ly0, ly1, lx0, "W")
        plan.rooms_beside(ry0, ry1, rx1, "E")
        plan.rooms_along(h0, h1, hy0, "S")


def _office(plan: _Plan, rng) -> tuple[list, tuple]:
    """Offices along one side of a corridor that opens into an open-plan area at one end."""
    w = _q(rng.uniform(1.8, 2.4))
    n = int(rng.integers(5, 8))
    length = _q(n * 3.6)
    corridor = (0.0, 0.0, length, w)
    area = (length, _q(-rng.uniform(2.0, 4.0)), _q(length + rng.uniform(7.0, 10.0)), _q(w + rng.uniform(4.0, 7.0)))
    plan.add(1, *corridor)
    plan.add(1, *area)
    plan.rooms_along(0.0, length, w, "N", depth=(3.2, 4.2), width=(3.0, 4.2))
    plan.rooms_along(0.0, length, 0.0, "S", depth=(3.0, 4.0), width=(3.6, 5.0))
    return [corridor], area


def _hall(plan: _Plan, rng) -> tuple[float, float, float, float]:
    wx, wy = _q(rng.uniform(12.0, 18.0)), _q(rng.uniform(9.0, 14.0))
    plan.add(1, 0.0, 0.0, wx, wy)
    if rng.random() < 0.7:  # a side room or two along the north wall
        plan.rooms_along(_q(wx * 0.55), wx, wy, "N", depth=(3.0, 4.0), width=(3.0, 4.0))
    return (0.0, 0.0, wx, wy)


def _furnish_open(b: Builder, rect, rng, tables: int) -> list[tuple[float, float]]:
    """Tables with chairs and a few pillars on a coarse lattice of an open area, leaving >= 1.8 m
    walkways; returns free points between them (start candidates)."""
    x0, y0, x1, y1 = rect
    step = 3.6
    xs = np.arange(x0 + 2.4, x1 - 1.8, step)
    ys = np.arange(y0 + 2.4, y1 - 1.8, step)
    spots = [(x, y) for x in xs for y in ys]
    order = rng.permutation(len(spots))
    used = set(order[:tables].tolist())
    free_pts = []
    for i, (x, y) in enumerate(spots):
        if i in used:
            if rng.random() < 0.25:
                b.cyl("pillar", x, y, 0.25, 2.5, (0.55, 0.55, 0.6))
            else:
                b.box("table", x, y, 1.4, 0.8, 0.75, b.color(), yaw=float(rng.choice([0.0, np.pi / 2])))
                b.cyl("chair", x + 0.95, y, 0.2, 0.8, b.color())
        free_pts.append((x + step / 2, y + step / 2))
    return [p for p in free_pts if x0 + 1.0 < p[0] < x1 - 1.0 and y0 + 1.0 < p[1] < y1 - 1.0]


def building(seed: int = 0, kind: str = "office") -> Layout:
    """A building of ``kind`` (one of :data:`KINDS`) drawn from ``seed`` (see the module docstring)."""
    from .layout_file import check_layout

    if kind not in KINDS:
        raise ValueError(f"unknown building kind {kind!r}; use one of {list(KINDS)}")
    b = Builder(seed)
    rng = b.rng
    plan = _Plan(rng)
    extra_pts: list = []
    if kind == "office":
        arms, area = _office(plan, rng)
        open_rects = [area]
    elif kind == "hall":
        hall = _hall(plan, rng)
        arms, open_rects = [], [hall]
    else:
        arms = _corridor_shape(plan, kind, rng)
        _rooms_for(plan, kind, arms)
        open_rects = []
    colors = {r["label"]: b.color() for r in plan.rooms}
    _walls(b, plan, colors)
    for r in plan.rooms:
        _furnish_room(b, r)
    for rect in open_rects:
        extra_pts += _furnish_open(b, rect, rng, tables=int(rng.integers(4, 10)))
    g, ox, oy = plan.grid()
    bounds = (ox - WALL, oy - WALL, ox + g.shape[1] * U + WALL, oy + g.shape[0] * U + WALL)
    starts = _starts(rng, _corridor_points(arms), plan.rooms, extra_pts)
    layout = Layout(f"building_{kind}", tuple(float(v) for v in bounds), tuple(b.shapes), (), None, seed)
    return check_layout(layout, starts, f"building(seed={seed}, kind={kind!r})")



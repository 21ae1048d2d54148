"""Seeded room layouts as pure data: named boxes and cylinders, bounds, start poses.

Every builder takes a `seed` (object jitter, which slots hold cars, ...) and returns a
`Layout`. Interiors start at (0, 0); outer walls sit outside the interior. Floor sizes
are chosen so that the free area reachable from the first start (see
`occupancy.OccupancyGrid.free_area`) matches the paper's figure for that environment.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

# the room record and wall constants live in .layout_builder; importable from here as before
from .layout_builder import OPENING, WALL, WALL_H, Builder, Layout, Pose, wall_segments  # noqa: F401

SIDE_COLORS = ((0.85, 0.3, 0.25), (0.25, 0.55, 0.85), (0.3, 0.75, 0.35), (0.9, 0.8, 0.3))
RACK = (0.2, 0.35, 0.75)
PALLET = (0.75, 0.55, 0.3)
FORKLIFT = (0.95, 0.7, 0.1)


def _forklift(b: Builder, x, y, yaw):
    """Body box, two thin forks and two mast legs (hard for a planar LiDAR)."""
    c, s = np.cos(yaw), np.sin(yaw)
    b.box("forklift", x, y, 1.4, 0.9, 1.2, FORKLIFT, yaw)
    for off in (-0.25, 0.25):
        fx, fy = x + c * 1.15 - s * off, y + s * 1.15 + c * off
        b.box("fork", fx, fy, 0.9, 0.08, 0.35, (0.2, 0.2, 0.2), yaw)
        b.cyl("mast", x + c * 0.72 - s * off, y + s * 0.72 + c * off, 0.05, 1.8, (0.2, 0.2, 0.2))


def mini_warehouse(seed: int = 0) -> Layout:
    """About 36 m2: an open room with a movable central box and a few pallets."""
    b = Builder(seed)
    w, h = 6.6, 6.0
    bounds = b.enclosure(w, h, SIDE_COLORS)
    b.box("box", w / 2, h / 2, 1.2, 1.2, 1.0, (0.85, 0.45, 0.1), movable=True,
          name="central_box")
    b.box("pallet", 0.6 + b.jitter(0.1), 5.3 + b.jitter(0.1), 0.9, 0.9, 0.8, PALLET)
    b.box("pallet", 5.9 + b.jitter(0.1), 0.7 + b.jitter(0.1), 0.9, 0.9, 0.8, PALLET)
    b.cyl("barrel", 5.9 + b.jitter(0.1), 5.4 + b.jitter(0.1), 0.3, 0.9, (0.1, 0.5, 0.3))
    return b.layout("mini_warehouse", bounds, [(1.2, 1.2, 0.0), (5.2, 3.0, np.pi / 2),
                                               (1.5, 4.2, 0.0), (3.3, 5.2, np.pi)], 36.0)


def small_warehouse(seed: int = 0) -> Layout:
    """About 80 m2: two rack rows and some pallets and barrels."""
    b = Builder(seed)
    w, h = 10.4, 8.8
    bounds = b.enclosure(w, h, SIDE_COLORS)
    for y in (3.0, 5.8):
        b.box("rack", 5.2, y, 5.0, 0.8, 2.0, RACK)
    for x, y in ((0.7, 0.7), (9.6, 8.0), (9.6, 0.7)):
        b.box("pallet", x + b.jitter(0.1), y + b.jitter(0.1), 0.9, 0.9, 0.8, PALLET)
    b.cyl("barrel", 1.0 + b.jitter(0.1), 7.9, 0.3, 0.9, (0.1, 0.5, 0.3))
    return b.layout("small_warehouse", bounds,
                    [(1.0, 4.4, 0.0), (8.5, 4.4, np.pi), (5.0, 1.3, 0.0), (5.0, 7.6, 0.0)],
                    80.0)


def large_warehouse(seed: int = 0) -> Layout:
    """About 280 m2: four long rack rows forming aisles, forklifts and pallets."""
    b = Builder(seed)
    w, h = 22.0, 16.2
    bounds = b.enclosure(w, h, SIDE_COLORS)
    rack_colors = [(0.2, 0.35, 0.75), (0.75, 0.2, 0.3), (0.2, 0.6, 0.55), (0.55, 0.3, 0.7)]
    for i, y in enumerate((3.3, 6.6, 9.9, 13.2)):
        b.box("rack", 11.0, y, 14.0, 1.0, 2.2, rack_colors[i])
    _forklift(b, 2.0, 1.4 + b.jitter(0.2), 0.0)
    # racks span x 4-18, y 2.8-13.7: forklifts leave >= 1.6 m to the rack ends and rows
    _forklift(b, 20.2, 8.2 + b.jitter(0.2), np.pi / 2)
    _forklift(b, 9.0 + b.jitter(0.5), 15.75, np.pi)
    for _ in range(6):
        x = float(b.rng.choice([1.0, 21.3]))
        y = float(b.rng.uniform(3.0, 14.0))
        b.box("pallet", x, y, 1.0, 1.0, 0.9, PALLET)
    return b.layout("large_warehouse", bounds,
                    [(11.0, 1.5, 0.0), (3.0, 8.2, 0.0), (11.0, 5.0, 0.0), (16.0, 11.5, np.pi)],
                    280.0)


def house(seed: int = 0) -> Layout:
    """About 175 m2: kitchen, living room, playroom, three bedrooms, a hallway; no doors."""
    b = Builder(seed)
    w, h = 17.0, 12.3
    bounds = b.enclosure(w, h, [(0.85, 0.85, 0.8)] * 4)
    t = 0.12
    kitchen, play = (0.95, 0.9, 0.55), (0.95, 0.7, 0.85)
    # interior walls with doorless openings
    def door(mid):
        return (mid - OPENING / 2, mid + OPENING / 2)

    b.hwall(6.5, 0.0, w, gaps=[door(6.8), door(14.4)], t=t)
    b.vwall(5.0, 0.0, 6.5, gaps=[door(3.2)], t=t, color=kitchen)
    b.vwall(12.0, 0.0, 6.5, gaps=[door(2.0)], t=t, color=play)
    b.vwall(5.5, 6.5, h, gaps=[door(9.3)], t=t, color=(0.8, 0.9, 0.7))
    b.vwall(8.0, 6.5, h, gaps=[door(10.5)], t=t, color=(0.9, 0.8, 0.6))
    b.vwall(12.5, 6.5, h, t=t, color=(0.75, 0.75, 0.95))
    # kitchen (x 0-5, y 0-6.5)
    b.box("counter", 0.3, 3.2, 0.6, 4.0, 0.9, (0.55, 0.4, 0.3))
    b.box("island", 2.6 + b.jitter(0.1), 1.6, 1.6, 0.8, 0.9, (0.45, 0.3, 0.25))
    b.box("table", 2.8, 4.6 + b.jitter(0.1), 1.4, 0.9, 0.75, (0.8, 0.6, 0.35))
    for dx in (-0.45, 0.45):
        for dy in (-0.7, 0.7):
            b.cyl("chair", 2.8 + dx, 4.6 + dy, 0.2, 0.8, (0.3, 0.2, 0.15))
    # living room (x 5-12, y 0-6.5)
    b.box("sofa", 8.5 + b.jitter(0.2), 0.55, 2.4, 0.9, 0.8, (0.35, 0.45, 0.6))
    b.box("coffee_table", 8.5, 2.1, 1.1, 0.6, 0.45, (0.6, 0.45, 0.3))
    b.box("tv_stand", 8.5, 4.6, 1.8, 0.45, 0.6, (0.15, 0.15, 0.15))
    b.cyl("armchair", 6.2, 1.2, 0.45, 0.8, (0.7, 0.3, 0.3))
    b.cyl("plant", 11.5, 6.0, 0.25, 1.2, (0.2, 0.6, 0.2))
    # playroom (x 12-17, y 0-6.5)
    b.box("toy_box", 16.4, 0.6, 0.8, 0.8, 0.5, (0.95, 0.3, 0.3))
    b.box("play_table", 14.5 + b.jitter(0.2), 3.2, 1.2, 0.8, 0.5, (0.3, 0.75, 0.95))
    b.cyl("bean_bag", 16.2, 5.2, 0.45, 0.6, (0.95, 0.6, 0.1))
    b.cyl("bean_bag", 13.0, 5.6, 0.4, 0.6, (0.5, 0.3, 0.8))
    # bedroom 1 (x 0-5.5, y 6.5-12)
    b.box("bed", 1.2, 10.0, 2.0, 1.6, 0.5, (0.9, 0.9, 0.95))
    b.box("wardrobe", 4.5, h - 0.4, 1.4, 0.6, 2.0, (0.5, 0.35, 0.2))
    b.box("desk", 0.4, 7.5, 0.6, 1.2, 0.75, (0.7, 0.6, 0.4))
    # hallway (x 5.5-8)
    b.box("shelf", 6.75, h - 0.25, 1.2, 0.35, 1.8, (0.4, 0.4, 0.45))
    # bedroom 2 (x 8-12.5)
    b.box("bed", 11.2, 9.3, 2.0, 1.0, 0.5, (0.6, 0.8, 0.6))
    b.box("wardrobe", 10.0, 6.95, 1.2, 0.6, 2.0, (0.45, 0.3, 0.2))
    # bedroom 3 (x 12.5-17)
    b.box("bed", 16.0, 10.4, 2.0, 1.6, 0.5, (0.95, 0.85, 0.6))
    b.box("wardrobe", 13.1, h - 0.8, 0.6, 1.2, 2.0, (0.55, 0.35, 0.25))
    b.cyl("chair", 13.3 + b.jitter(0.1), 8.4, 0.25, 0.8, (0.3, 0.3, 0.6))
    return b.layout("house", bounds,
                    [(8.5, 3.2, 0.0), (2.5, 3.2, 0.0), (14.5, 1.5, np.pi / 2),
                     (6.75, 9.0, np.pi / 2), (3.0, 8.2, 0.0)], 175.0)


def bedroom(seed: int = 0) -> Layout:
    """About 20 m2: bed, nightstands, wardrobe, desk and chair."""
    b = Builder(seed)
    w, h = 5.45, 4.9
    bounds = b.enclosure(w, h, [(0.9, 0.85, 0.7), (0.7, 0.8, 0.9), (0.9, 0.85, 0.7),
                                (0.8, 0.7, 0.85)])
    b.box("bed", 1.1, 3.4, 2.2, 1.6, 0.5, (0.85, 0.85, 0.95))  # headboard on west wall
    b.box("nightstand", 0.25, 4.55, 0.45, 0.45, 0.55, (0.55, 0.4, 0.3))
    b.box("nightstand", 0.25, 2.3, 0.45, 0.45, 0.55, (0.55, 0.4, 0.3))
    b.box("wardrobe", w - 0.7, 4.6, 1.3, 0.6, 2.0, (0.5, 0.35, 0.2))
    b.box("desk", w - 0.35, 1.2 + b.jitter(0.1), 0.6, 1.1, 0.75, (0.7, 0.6, 0.4))
    b.cyl("chair", w - 1.0, 1.2, 0.25, 0.8, (0.2, 0.3, 0.6), movable=True)
    return b.layout("bedroom", bounds, [(2.0, 1.2, 0.0), (3.2, 3.0, np.pi / 2),
                                        (1.0, 0.8, 0.0)], 20.3)


CAR_COLORS = [(0.8, 0.1, 0.1), (0.1, 0.2, 0.7), (0.9, 0.9, 0.9), (0.15, 0.15, 0.15),
              (0.2, 0.6, 0.3), (0.95, 0.75, 0.1), (0.6, 0.6, 0.65)]


def parking_lot(seed: int = 0, n_cars: int = 12) -> Layout:
    """About 325 m2: two rows of parking slots along the long walls; cars are movable."""
    b = Builder(seed)
    w, h = 26.0, 16.6
    bounds = b.enclosure(w, h, [(0.6, 0.6, 0.6), (0.7, 0.55, 0.45), (0.6, 0.6, 0.6),
                                (0.45, 0.55, 0.7)])
    slots = [(2.2 + 2.7 * i, y) for y in (2.5, h - 2.5) for i in range(9)]
    chosen = sorted(b.rng.choice(len(slots), size=min(n_cars, len(slots)), replace=False))
    for i in chosen:
        x, y = slots[i]
        col = CAR_COLORS[int(b.rng.integers(len(CAR_COLORS)))]
        b.box("car", x + b.jitter(0.15), y + b.jitter(0.15), 1.8, 4.4, 1.5, col,
              yaw=b.jitter(0.06), movable=True)
    b.box("booth", w - 1.0, h / 2, 1.5, 1.5, 2.2, (0.9, 0.9, 0.6))
    for x in (6.0, 13.0, 20.0):
        b.cyl("lamp_post", x, h / 2, 0.12, 3.0, (0.3, 0.3, 0.3))
    return b.layout("parking_lot", bounds, [(2.0, h / 2, 0.0), (13.0, h / 2 + 1.0, np.pi),
                                            (22.0, h / 2 - 1.5, 0.0)], 325.0)


def aisle_warehouse(seed: int = 0) -> Layout:
    """About 185 m2: three rack rows forming two long aisles, and an open area."""
    b = Builder(seed)
    w, h = 19.2, 12.0
    bounds = b.enclosure(w, h, SIDE_COLORS)
    # rows at x 1.6-13.6 and y 1.6-2.6, 4.9-5.9, 8.2-9.2: aisles, side strips and the
    # passages at the row ends are all >= 1.6 m wide
    for y, col in ((2.1, (0.2, 0.35, 0.75)), (5.4, (0.75, 0.3, 0.2)), (8.7, (0.2, 0.6, 0.4))):
        b.box("rack", 7.6, y, 12.0, 1.0, 2.2, col)
    for _ in range(4):  # against the east wall, clear of the pillars
        b.box("pallet", 18.5 + b.jitter(0.1), b.rng.uniform(1.5, 10.5),
              1.0, 1.0, 0.9, PALLET)
    for x, y in ((15.5, 4.0), (15.5, 8.0)):
        b.cyl("pillar", x, y, 0.2, 2.5, (0.5, 0.5, 0.55))
    return b.layout("aisle_warehouse", bounds,
                    [(14.5, 6.0, np.pi), (7.5, 3.75, 0.0), (7.5, 7.05, np.pi), (0.8, 10.5, 0.0)],
                    185.0)


def random_rooms(seed: int = 0, n_x: int = 3, n_y: int = 2, size=(3.0, 6.0),
                 door: float = OPENING, furniture: int = 2) -> Layout:
    """A grid of rooms with random sizes, doorless openings forming a connected plan."""
    b = Builder(seed)
    rng = b.rng
    xs = np.concatenate([[0.0], np.cumsum(rng.uniform(*size, n_x))])
    ys = np.concatenate([[0.0], np.cumsum(rng.uniform(*size, n_y))])
    w, h = float(xs[-1]), float(ys[-1])
    colors = [b.color() for _ in range(4)]
    bounds = b.enclosure(w, h, colors)
    # spanning tree over rooms by random depth-first search: every room is reachable
    seen, stack, edges = {0}, [0], set()
    while stack:
        cur = stack[-1]
        i, j = divmod(cur, n_y)
        nbrs = [(i + di) * n_y + (j + dj) for di, dj in ((1, 0), (-1, 0), (0, 1), (0, -1))
                if 0 <= i + di < n_x and 0 <= j + dj < n_y]
        nbrs = [m for m in nbrs if m not in seen]
        if not nbrs:
            stack.pop()
            continue
        m = int(rng.choice(nbrs))
        edges.add((min(cur, m), max(cur, m)))
        seen.add(m)
        stack.append(m)

    doors = []

    def gap(a, c):
        mid = rng.uniform(a + door / 2 + 0.3, c - door / 2 - 0.3)
        return (mid - door / 2, mid + door / 2)

    for i in range(1, n_x):  # vertical walls between column i-1 and i
        gaps = [gap(ys[j], ys[j + 1]) for j in range(n_y)
                if ((i - 1) * n_y + j, i * n_y + j) in edges]
        doors += [(xs[i], (g0 + g1) / 2) for g0, g1 in gaps]
        b.vwall(xs[i], 0.0, h, gaps, color=b.color())
    for j in range(1, n_y):
        gaps = [gap(xs[i], xs[i + 1]) for i in range(n_x)
                if (i * n_y + j - 1, i * n_y + j) in edges]
        doors += [((g0 + g1) / 2, ys[j]) for g0, g1 in gaps]
        b.hwall(ys[j], 0.0, w, gaps, color=b.color())
    starts = []
    for i in range(n_x):
        for j in range(n_y):
            cx, cy = (xs[i] + xs[i + 1]) / 2, (ys[j] + ys[j + 1]) / 2
            starts.append((cx, cy, 0.0))
            for _ in range(furniture * 10):  # against a wall, away from centre and doors
                if sum(k.startswith("furniture") for k in b.names()) >= furniture * (
                        i * n_y + j + 1):
                    break
                sx, sy = rng.uniform(0.4, 1.0, 2)
                side = int(rng.integers(4))
                if side < 2:
                    x = xs[i] + 0.1 + sx / 2 if side == 0 else xs[i + 1] - 0.1 - sx / 2
                    y = rng.uniform(ys[j] + 0.8, ys[j + 1] - 0.8)
                else:
                    y = ys[j] + 0.1 + sy / 2 if side == 2 else ys[j + 1] - 0.1 - sy / 2
                    x = rng.uniform(xs[i] + 0.8, xs[i + 1] - 0.8)
                if min(np.hypot(x - dx, y - dy) for dx, dy in doors) > door + 1.0:
                    b.box("furniture", x, y, sx, sy, 0.8, b.color())
    return b.layout("random_rooms", bounds, starts, None)


def _building(seed: int = 0, kind: str = "office") -> Layout:
    """The procedural building family (:mod:`cogmap.envs.buildings`)."""
    from .buildings import building

    return building(seed, kind)


LAYOUTS: dict[str, Callable[..., Layout]] = {
    "mini_warehouse": mini_warehouse,
    "small_warehouse": small_warehouse,
    "large_warehouse": large_warehouse,
    "house": house,
    "bedroom": bedroom,
    "parking_lot": parking_lot,
    "aisle_warehouse": aisle_warehouse,
    "random_rooms": random_rooms,
    "building": _building,
}


def make_layout(name: str, seed: int = 0, **kwargs) -> Layout:
    """Build a layout by name (see ``LAYOUTS``).

    Parameters
    ----------
    name : str
        Layout name, e.g. ``"house"`` or ``"building"``.
    seed : int, optional
        Seed of the layout's random parts (furniture jitter, procedural plans).
    **kwargs
        Passed to the layout's builder (e.g. ``kind`` for ``"building"``).

    Returns
    -------
    Layout
        The layout.

    Raises
    ------
    KeyError
        When no layout has that name (the message lists the known ones).
    """
    try:
        return LAYOUTS[name](seed, **kwargs)
    except KeyError:
        raise KeyError(f"unknown layout {name!r}; known: {sorted(LAYOUTS)}") from None

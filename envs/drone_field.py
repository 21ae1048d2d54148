"""Seeded 3D obstacle fields for the drone (no pybullet here: pure geometry).

A field of about 200 x 200 m around the start (the origin): houses (boxes), trees (a cylinder
trunk and a sphere crown), narrow alleys (rows of long buildings with 3-5 m gaps) and dense bands
(strips of closely planted trees), over a ground plane at z = 0. The start keeps a clear zone.
:meth:`Field.distance` is the exact signed distance to the nearest surface (ground included), used
to keep targets outside geometry; the simulator builds the same shapes in pybullet.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Block:
    """Axis-aligned box: centre (x, y, z) and full sizes (sx, sy, sz)."""

    x: float
    y: float
    z: float
    sx: float
    sy: float
    sz: float
    kind: str = "house"


@dataclass(frozen=True)
class Trunk:
    """Vertical cylinder standing on the ground: centre (x, y), radius, height."""

    x: float
    y: float
    radius: float
    height: float


@dataclass(frozen=True)
class Crown:
    """Sphere: centre (x, y, z) and radius."""

    x: float
    y: float
    z: float
    radius: float


@dataclass(frozen=True)
class FieldConfig:
    half_size: float = 100.0  # the field spans [-half, half]^2
    n_houses: int = 80
    n_trees: int = 350
    n_alleys: int = 6
    n_bands: int = 5
    clear_radius: float = 6.0  # around the start
    start_altitude: float = 3.0


@dataclass(frozen=True)
class Field:
    blocks: tuple[Block, ...]
    trunks: tuple[Trunk, ...]
    crowns: tuple[Crown, ...]
    half_size: float
    start: tuple[float, float, float]
    seed: int

    @property
    def n_shapes(self) -> int:
        return len(self.blocks) + len(self.trunks) + len(self.crowns)

    def distance(self, points) -> np.ndarray:
        """Signed distance (m) from each point (N, 3) to the nearest surface, ground included
        (negative inside a shape or below the ground)."""
        P = np.asarray(points, float).reshape(-1, 3)
        best = P[:, 2].copy()  # ground plane z = 0
        if self.blocks:
            B = np.array([[b.x, b.y, b.z, b.sx / 2, b.sy / 2, b.sz / 2] for b in self.blocks])
            q = np.abs(P[:, None, :] - B[None, :, :3]) - B[None, :, 3:]
            out = np.linalg.norm(np.maximum(q, 0.0), axis=2)
            inside = np.minimum(q.max(2), 0.0)
            best = np.minimum(best, (out + inside).min(1))
        if self.trunks:
            T = np.array([[t.x, t.y, t.radius, t.height] for t in self.trunks])
            dr = np.hypot(P[:, None, 0] - T[None, :, 0], P[:, None, 1] - T[None, :, 1]) - T[None, :, 2]
            dz = np.abs(P[:, None, 2] - T[None, :, 3] / 2) - T[None, :, 3] / 2
            q = np.stack([dr, dz], 2)
            d = np.linalg.norm(np.maximum(q, 0.0), axis=2) + np.minimum(q.max(2), 0.0)
            best = np.minimum(best, d.min(1))
        if self.crowns:
            C = np.array([[c.x, c.y, c.z, c.radius] for c in self.crowns])
            d = np.linalg.norm(P[:, None, :] - C[None, :, :3], axis=2) - C[None, :, 3]
            best = np.minimum(best, d.min(1))
        return best

    def bounds3(self):
        """Axis-aligned bounds (lo, hi) of every shape, (M, 3) each, in the order blocks, trunks,
        crowns (the order the simulator creates bodies in)."""
        lo, hi = [], []
        for b in self.blocks:
            h = np.array([b.sx, b.sy, b.sz]) / 2
            lo.append(np.array([b.x, b.y, b.z]) - h)
            hi.append(np.array([b.x, b.y, b.z]) + h)
        for t in self.trunks:
            lo.append(np.array([t.x - t.radius, t.y - t.radius, 0.0]))
            hi.append(np.array([t.x + t.radius, t.y + t.radius, t.height]))
        for c in self.crowns:
            lo.append(np.array([c.x, c.y, c.z]) - c.radius)
            hi.append(np.array([c.x, c.y, c.z]) + c.radius)
        return np.array(lo).reshape(-1, 3), np.array(hi).reshape(-1, 3)


def _tree(rng, x, y, small: bool = False):
    trunk_h = rng.uniform(2.0, 4.0) if small else rng.uniform(2.5, 6.0)
    crown_r = rng.uniform(1.0, 2.0) if small else rng.uniform(1.5, 3.0)
    return Trunk(x, y, rng.uniform(0.15, 0.35), trunk_h), Crown(x, y, trunk_h + 0.6 * crown_r, crown_r)


def make_field(seed: int = 0, config: FieldConfig | None = None) -> Field:
    """A seeded field: houses, alleys, dense bands of trees, scattered trees (see module doc)."""
    c = config or FieldConfig()
    rng = np.random.default_rng([seed, 7231])
    H = c.half_size
    blocks: list[Block] = []
    trunks: list[Trunk] = []
    crowns: list[Crown] = []

    def clear_of_start(x, y, extent):
        return np.hypot(x, y) > c.clear_radius + extent

    for _ in range(c.n_alleys):  # two rows of long buildings with a narrow gap between them
        cx, cy = rng.uniform(-0.8 * H, 0.8 * H, 2)
        length = rng.uniform(20.0, 40.0)
        gap = rng.uniform(3.0, 5.0)
        depth = rng.uniform(5.0, 8.0)
        height = rng.uniform(6.0, 14.0)
        along_x = rng.random() < 0.5
        if not clear_of_start(cx, cy, length / 2 + depth + gap):
            continue
        for side in (-1, 1):
            off = side * (gap / 2 + depth / 2)
            if along_x:
                blocks.append(Block(cx, cy + off, height / 2, length, depth, height, "alley"))
            else:
                blocks.append(Block(cx + off, cy, height / 2, depth, length, height, "alley"))
    for _ in range(c.n_houses):
        x, y = rng.uniform(-H, H, 2)
        sx, sy = rng.uniform(6.0, 14.0, 2)
        h = rng.uniform(4.0, 12.0)
        if clear_of_start(x, y, max(sx, sy) / 2 * 1.42):
            blocks.append(Block(x, y, h / 2, sx, sy, h, "house"))
    for _ in range(c.n_bands):  # a strip of closely planted trees
        x0, y0 = rng.uniform(-0.7 * H, 0.7 * H, 2)
        ang = rng.uniform(0, np.pi)
        u = np.array([np.cos(ang), np.sin(ang)])
        n = np.array([-u[1], u[0]])
        length = rng.uniform(50.0, 90.0)
        for s in np.arange(-length / 2, length / 2, 3.5):
            for w in (-3.5, 0.0, 3.5):
                xy = np.array([x0, y0]) + s * u + w * n + rng.uniform(-0.8, 0.8, 2)
                if abs(xy).max() < H and clear_of_start(*xy, 3.0):
                    t, k = _tree(rng, *xy, small=True)
                    trunks.append(t)
                    crowns.append(k)
    for _ in range(c.n_trees):
        x, y = rng.uniform(-H, H, 2)
        if clear_of_start(x, y, 3.0):
            t, k = _tree(rng, x, y)
            trunks.append(t)
            crowns.append(k)
    return Field(tuple(blocks), tuple(trunks), tuple(crowns), H, (0.0, 0.0, c.start_altitude), int(seed))


def sample_target(field: Field, rng: np.random.Generator, min_dist: float = 15.0, max_dist: float = 100.0,
                  min_alt: float = 2.0, max_alt: float = 20.0, clearance: float = 1.5, tries: int = 500,
                  ray_check=None) -> np.ndarray:
    """A target 15-100 m (horizontally) from the start at 2-20 m altitude, at least ``clearance``
    from every surface; ``ray_check(point) -> bool`` (the simulator's ray-cast validation) must
    accept it when given."""
    s = np.asarray(field.start, float)
    for _ in range(tries):
        r = rng.uniform(min_dist, max_dist)
        a = rng.uniform(-np.pi, np.pi)
        p = np.array([s[0] + r * np.cos(a), s[1] + r * np.sin(a), rng.uniform(min_alt, max_alt)])
        if abs(p[:2]).max() > field.half_size - 2:
            continue
        if field.distance(p)[0] < clearance:
            continue
        if ray_check is not None and not ray_check(p):
            continue
        return p
    raise RuntimeError(f"sample_target: no free target found in {tries} tries (field seed {field.seed})")

"""Seeded place samples for measuring how panoramas change with position.

Used by the place-recognition test and `bench/envs.py --ssim`: pairs of free, mutually
reachable positions a given distance apart (with a clear straight segment between them),
and pairs of free positions at least a given distance apart.
"""

from __future__ import annotations

import numpy as np

from .geometry import ShapeSet

CLEARANCE = 0.35  # robot radius plus a margin


def _free_sampler(sim, rng: np.random.Generator, clearance: float):
    shapes = ShapeSet(sim.layout.shapes)
    grid = sim.grid
    reach = grid.reachable(sim.layout.starts[0][:2])
    xmin, ymin, xmax, ymax = sim.layout.bounds

    def ok(pts) -> bool:
        pts = np.asarray(pts, float).reshape(-1, 2)
        if not (shapes.distance(pts) > clearance).all():
            return False
        rc = grid.world_to_cell(pts)
        return bool(reach[rc[:, 0], rc[:, 1]].all())

    def draw() -> np.ndarray:
        return rng.uniform([xmin, ymin], [xmax, ymax])

    return ok, draw


def _pairs(sim, n: int, rng: np.random.Generator, clearance: float, max_tries: int, propose) -> list:
    """Up to ``n`` pairs ``propose(draw, ok)`` returns (None: rejected), in at most ``max_tries`` draws."""
    ok, draw = _free_sampler(sim, rng, clearance)
    out = []
    for _ in range(max_tries):
        if len(out) == n:
            break
        pair = propose(draw, ok)
        if pair is not None:
            out.append(pair)
    return out


def displaced_pairs(sim, dx: float, n: int, rng: np.random.Generator,
                    clearance: float = CLEARANCE, max_tries: int = 100_000):
    """n pairs (a, b) with |b - a| = dx in a random direction, the segment clear."""

    def propose(draw, ok):
        a = draw()
        th = rng.uniform(0, 2 * np.pi)
        b = a + dx * np.array([np.cos(th), np.sin(th)])
        return (a, b) if ok(a + np.linspace(0, 1, 12)[:, None] * (b - a)) else None

    return _pairs(sim, n, rng, clearance, max_tries, propose)


def distant_pairs(sim, d_min: float, n: int, rng: np.random.Generator,
                  clearance: float = CLEARANCE, max_tries: int = 100_000):
    """n pairs of free reachable places at least d_min apart."""

    def propose(draw, ok):
        a, b = draw(), draw()
        return (a, b) if np.hypot(*(a - b)) >= d_min and ok(np.stack([a, b])) else None

    return _pairs(sim, n, rng, clearance, max_tries, propose)


def panorama_at(sim, xy) -> np.ndarray:
    """Teleport keeping the true yaw (odometry unchanged) and return the panorama."""
    sim.teleport((float(xy[0]), float(xy[1]), float(sim.true_pose()[2])))
    return sim.panorama()

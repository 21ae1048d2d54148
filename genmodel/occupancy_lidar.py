"""LiDAR on a known occupancy grid: expected ranges by ray marching and a beam likelihood.

The measurement model of grid-based Monte Carlo localisation (Thrun, Burgard and Fox, Probabilistic
Robotics, ch. 6.3 "beam model"): the expected range of each beam is found by marching along it through a
boolean occupancy raster until the first occupied cell; the observed range is Gaussian around it, mixed
with a uniform floor over ``[0, max_range]`` for unmodelled returns. Beam ``k`` of ``n`` points at
``heading + 2 pi k / n`` (the maze LiDAR of :mod:`cogmap.envs.maze_sim`). Pure jax functions of arrays.
"""

from __future__ import annotations

import jax.numpy as jnp


def march_samples(max_range: float, step: float) -> jnp.ndarray:
    """Distances ``(K,)`` along a beam at which the raster is read: ``step, 2 step, ... <= max_range``."""
    if step <= 0 or max_range <= 0:
        raise ValueError(f"march_samples: need step > 0 and max_range > 0, got {step}, {max_range}")
    return jnp.arange(1, int(max_range / step) + 1) * step


def expected_ranges(occ, extent: float, poses, n_beams: int, max_range: float, step: float):
    """Ranges ``(N, n_beams)`` at which beams from ``poses (N, 3)`` first meet an occupied cell of
    ``occ (R, R)`` (bool, ``occ[ix, iy]`` covers ``[ix, ix + 1) * extent / R`` in x, the layout of
    :meth:`cogmap.envs.maze.Maze.occupancy`); ``max_range`` where none is met within it. Points outside
    the raster count as occupied (the outer wall). Resolution: ``step`` (keep it below a cell side so a
    wall cannot be stepped over)."""
    occ = jnp.asarray(occ, bool)
    res = occ.shape[0]
    s = march_samples(max_range, step)
    poses = jnp.atleast_2d(jnp.asarray(poses, float))
    ang = poses[:, 2:3] + 2 * jnp.pi * jnp.arange(n_beams) / n_beams  # (N, B)
    px = poses[:, 0, None, None] + jnp.cos(ang)[..., None] * s  # (N, B, K)
    py = poses[:, 1, None, None] + jnp.sin(ang)[..., None] * s
    ix = jnp.floor(px / extent * res).astype(int)
    iy = jnp.floor(py / extent * res).astype(int)
    inside = (ix >= 0) & (ix < res) & (iy >= 0) & (iy < res)
    hit = ~inside | occ[jnp.clip(ix, 0, res - 1), jnp.clip(iy, 0, res - 1)]
    first = jnp.argmax(hit, axis=-1)
    return jnp.where(hit.any(-1), s[first], max_range)


def beam_log_likelihood(expected, observed, sigma: float, floor: float, max_range: float):
    """``sum_k log[(1 - floor) N(x_k; r_k, sigma^2) + floor / max_range]`` per row: ``expected (N, B)``
    against ``observed (B,)``, returning ``(N,)``."""
    d = (jnp.asarray(observed, float) - expected) / sigma
    gauss = jnp.exp(-0.5 * d**2) / (sigma * jnp.sqrt(2 * jnp.pi))
    return jnp.sum(jnp.log((1.0 - floor) * gauss + floor / max_range), -1)

"""Local charts: bilinear attention on the latent map at rotated, translated query points.

The map grid covers ``[0, extent]^2``; cell ``(i, j)`` has its centre at
``((i + 0.5) * extent / w, (j + 0.5) * extent / h)``. A point reads the convex combination of
the four surrounding cells with bilinear weights (paper III-B: ``m_t = sum_ij alpha(z_t)_ij M_ij``
with a bilinear kernel); points beyond the outer cell centres read the border cells.

The chart at a pose ``z = (x, y, phi)`` is the read at query points placed along each LiDAR beam:
point ``(k, r)`` lies at distance ``radii[r]`` in direction ``phi + 2 pi k / n_beams``. Rotating the
query points with the heading makes the chart agent-centric, so one emission network, shared
over beams, serves every orientation (the paper achieves the same with a rotational shift of the
emission output, Appendix B-A).
"""

from __future__ import annotations

import jax
import jax.numpy as jnp


def _axis(coord, n: int, extent: float):
    u = coord / (extent / n) - 0.5
    i0 = jnp.clip(jnp.floor(u), 0, n - 2).astype(jnp.int32)
    f = jnp.clip(u - i0, 0.0, 1.0)
    return i0, f


def bilinear_read(grid: jax.Array, points: jax.Array, extent: float, power: int = 1) -> jax.Array:
    """Read ``grid (w, h, D)`` at world points ``(..., 2)``; returns ``(..., D)``.

    ``power=2`` weights the cells by the squared attention, which turns a grid of independent
    variances into the variance of the read (``Var sum_c a_c M_c = sum_c a_c^2 Var M_c``).
    """
    w, h = grid.shape[0], grid.shape[1]
    i0, fx = _axis(points[..., 0], w, extent)
    j0, fy = _axis(points[..., 1], h, extent)
    fx, fy = fx[..., None], fy[..., None]
    a00, a10, a01, a11 = (1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy
    if power != 1:
        a00, a10, a01, a11 = a00**power, a10**power, a01**power, a11**power
    return a00 * grid[i0, j0] + a10 * grid[i0 + 1, j0] + a01 * grid[i0, j0 + 1] + a11 * grid[i0 + 1, j0 + 1]


def attention_weights(point: jax.Array, shape: tuple[int, int], extent: float) -> jax.Array:
    """The attention ``alpha(z)_ij`` of one point as a dense ``(w, h)`` array (sums to 1)."""
    w, h = shape
    i0, fx = _axis(point[0], w, extent)
    j0, fy = _axis(point[1], h, extent)
    a = jnp.zeros((w, h))
    a = a.at[i0, j0].add((1 - fx) * (1 - fy)).at[i0 + 1, j0].add(fx * (1 - fy))
    return a.at[i0, j0 + 1].add((1 - fx) * fy).at[i0 + 1, j0 + 1].add(fx * fy)


def beam_query_points(pose: jax.Array, n_beams: int, radii: jax.Array) -> jax.Array:
    """Query points ``(n_beams, len(radii), 2)`` along the beams of ``pose = (x, y, phi)``."""
    ang = pose[2] + 2 * jnp.pi * jnp.arange(n_beams) / n_beams
    d = jnp.stack([jnp.cos(ang), jnp.sin(ang)], -1)
    return pose[:2] + radii[None, :, None] * d[:, None, :]


def chart(grid: jax.Array, pose: jax.Array, extent: float, n_beams: int, radii: jax.Array,
          power: int = 1) -> jax.Array:
    """The chart ``m_t = f_m(z_t, M)`` of shape ``(n_beams, len(radii), D)``."""
    return bilinear_read(grid, beam_query_points(pose, n_beams, radii), extent, power)

"""Monte Carlo localisation on a known occupancy grid: the stand-in for Cartographer in the DVBF-LM
SLAM comparison (paper Section IV-B). Cartographer (C++/ROS) is not available here; this filter gets
what a SLAM system has to estimate for free, the true map as an occupancy raster, so it is a
privileged reference, not a reproduction of Cartographer.

Bootstrap particle filter (:func:`cogmap.inference.particle_filter.pf_step`) over poses
``(x, y, heading)``:

* transition: the simulator's actuation model, ``heading += u_turn + N(0, rot_std^2)``, then forward
  ``u_fwd * (1 + N(0, trans_frac^2))`` along the new heading, plus a small position jitter so that
  identical particles separate after resampling;
* likelihood: the beam model of :mod:`cogmap.genmodel.occupancy_lidar` (ray marching in the raster).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import jax
import jax.numpy as jnp
import numpy as np

from cogmap.genmodel.occupancy_lidar import beam_log_likelihood, expected_ranges

from .particle_filter import pf_init, pf_step


@dataclass(frozen=True)
class MCLConfig:
    """Settings of :func:`mcl_localise`. Lengths in map units, angles in radians.

    Attributes
    ----------
    n_particles : int
        Particles (all start at the known start pose).
    sigma : float
        Standard deviation of a range around its ray-marched expectation.
    floor : float
        Weight of the uniform part of the beam likelihood.
    rot_std, trans_frac : float
        Actuation noise of the transition (turn std; forward std as a fraction of the step).
    jitter : float
        Position std added to every particle each step.
    resolution : int
        Pixels per side of the occupancy raster.
    seed : int
        Seed of the filter.
    """

    n_particles: int = 500
    sigma: float = 0.01
    floor: float = 0.05
    rot_std: float = 0.005
    trans_frac: float = 0.05
    jitter: float = 0.0005
    resolution: int = 200
    seed: int = 0

    def __post_init__(self):
        if self.n_particles < 1 or self.resolution < 2:
            raise ValueError(f"MCLConfig: need n_particles >= 1 and resolution >= 2, got {self}")
        if self.sigma <= 0 or not 0 <= self.floor < 1 or min(self.rot_std, self.trans_frac, self.jitter) < 0:
            raise ValueError(f"MCLConfig: need sigma > 0, 0 <= floor < 1 and non-negative noise, got {self}")

    def to_json(self) -> dict:
        """The settings as a JSON-ready dict."""
        return asdict(self)


def mcl_localise(occ, extent: float, start, controls, scans, cfg: MCLConfig, max_range: float):
    """Filter a traversal: ``controls (T - 1, 2)`` (turn, forward; control ``t`` moves pose ``t`` to
    ``t + 1``) and ``scans (T, B)``, from the known ``start (3,)`` on the raster ``occ (R, R)`` covering
    ``[0, extent]^2``.

    Returns
    -------
    means : numpy.ndarray, shape (T, 3)
        Weighted mean pose per step (heading as a circular mean).
    stds : numpy.ndarray, shape (T, 2)
        Weighted position standard deviation per step.
    particles : numpy.ndarray, shape (n_particles, 3)
        The final particles.
    """
    occ = jnp.asarray(occ, bool)
    controls = jnp.asarray(controls, float).reshape(-1, 2)
    scans = jnp.asarray(scans, float)
    if scans.ndim != 2 or scans.shape[0] != controls.shape[0] + 1:
        raise ValueError(f"mcl_localise: need scans (T, B) and controls (T - 1, 2), got {scans.shape}, "
                         f"{controls.shape}")
    if occ.ndim != 2 or occ.shape[0] != occ.shape[1] or occ.shape[0] != cfg.resolution:
        raise ValueError(f"mcl_localise: occ must be ({cfg.resolution}, {cfg.resolution}), got {occ.shape}")
    n_beams = scans.shape[1]
    step = 0.5 * extent / cfg.resolution  # half a pixel: a wall (>= 1 pixel) cannot be stepped over

    def log_lik(z, x):
        return beam_log_likelihood(expected_ranges(occ, extent, z, n_beams, max_range, step), x, cfg.sigma,
                                   cfg.floor, max_range)

    def transition(key, z, u):
        k1, k2, k3 = jax.random.split(key, 3)
        n = z.shape[0]
        h = z[:, 2] + u[0] + cfg.rot_std * jax.random.normal(k1, (n,))
        d = u[1] * (1.0 + cfg.trans_frac * jax.random.normal(k2, (n,)))
        xy = z[:, :2] + d[:, None] * jnp.stack([jnp.cos(h), jnp.sin(h)], 1)
        xy = xy + cfg.jitter * jax.random.normal(k3, (n, 2))
        return jnp.concatenate([xy, ((h + jnp.pi) % (2 * jnp.pi) - jnp.pi)[:, None]], 1)

    def summary(s):
        w = jnp.exp(s.log_weights)
        mean = w @ s.particles[:, :2]
        head = jnp.arctan2(w @ jnp.sin(s.particles[:, 2]), w @ jnp.cos(s.particles[:, 2]))
        std = jnp.sqrt(jnp.maximum(w @ (s.particles[:, :2] - mean) ** 2, 0.0))
        return jnp.concatenate([mean, head[None]]), std

    @jax.jit
    def run(key):
        z0 = jnp.tile(jnp.asarray(start, float)[None], (cfg.n_particles, 1))
        s0 = pf_init(z0, scans[0], log_lik)

        def body(s, inp):
            k, u, x = inp
            s, _ = pf_step(k, s, u, x, transition, log_lik)
            return s, summary(s)

        keys = jax.random.split(key, controls.shape[0])
        s, (means, stds) = jax.lax.scan(body, s0, (keys, controls, scans[1:]))
        m0, sd0 = summary(s0)
        return jnp.concatenate([m0[None], means]), jnp.concatenate([sd0[None], stds]), s.particles

    means, stds, particles = run(jax.random.PRNGKey(cfg.seed))
    return np.asarray(means), np.asarray(stds), np.asarray(particles)

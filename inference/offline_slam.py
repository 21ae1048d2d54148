"""Offline SLAM with DVBF-LM (paper Section IV, Appendix B-I): every time step of a recorded traversal
is optimised at once, instead of the online sweep of :mod:`cogmap.inference.online_slam`.

The pose posterior is the offline particle filter (:func:`cogmap.inference.chunked_filter.chunked_filter`:
chunks of 5 steps in order, a categorical proposal with 0.001 jitter at each chunk start, 1,000 particles,
emission std 0.01). Its particles, a few kept per step, are the cache of the ELBO (Eq. 3). The two
alternate in rounds: the first cache is path integration (the pose posterior under the prior map,
whose predicted scan is the same everywhere), then each round trains q(M) for ``train_iters`` Adam
steps on mini-batches drawn from the whole traversal and refilters the whole traversal under the new
map mean. The estimate is the last pass's weighted particle mean.

This module is the stateful shell; the filter lives in ``inference.chunked_filter`` and the ELBO in
``inference.elbo``.
"""

from __future__ import annotations

import functools
import time
from dataclasses import asdict, dataclass, field

import numpy as np

from cogmap.genmodel.dvbf import DVBFConfig

from .online_slam import SLAMResult, path_integration


@dataclass(frozen=True)
class OfflineConfig:
    """Offline-SLAM settings (defaults: the paper's Appendix B-I where it gives them).

    Attributes
    ----------
    n_particles : int
        Particles of the offline filter (paper: 1,000).
    chunk : int
        Steps per filter chunk (paper: 5).
    jitter : float
        Noise std added to the particles at each chunk start (paper: 0.001).
    pf_sigma : float
        Per-beam emission std used to weight particles (paper: 0.01).
    rounds : int
        Alternations of ELBO training and a full filter pass.
    train_iters : int
        Adam steps on the ELBO per round.
    batch : int
        Time steps per ELBO batch, drawn uniformly over the traversal.
    cache : int
        Particles kept per step for the ELBO.
    learning_rate : float
        Adam learning rate.
    init_std : tuple of float
        Std of the initial particles around the known start: (x m, y m, yaw rad).
    model : DVBFConfig
        The DVBF-LM model (map grid, emission, transition noise).
    freeze_emission : bool
        Keep the starting emission network fixed and learn only q(M).
    grow : bool
        Round ``r`` (from 0) of ``R`` trains on the first ``(r + 1) / R`` of the traversal only, so the
        map is learnt where the poses are already right before later steps lean on it.
    seed : int
        Seed of the filter's and training's random numbers.
    """

    n_particles: int = 1000
    chunk: int = 5
    jitter: float = 0.001
    pf_sigma: float = 0.01
    rounds: int = 4
    train_iters: int = 1000
    batch: int = 64
    cache: int = 8
    learning_rate: float = 1e-2
    init_std: tuple[float, float, float] = (0.001, 0.001, 0.005)
    model: DVBFConfig = field(default_factory=DVBFConfig)
    freeze_emission: bool = False
    grow: bool = False
    seed: int = 0

    def __post_init__(self):
        if self.n_particles < 1 or self.chunk < 1 or self.rounds < 1 or self.cache < 1 or self.batch < 1:
            raise ValueError(f"OfflineConfig: sizes must be >= 1, got {self}")
        if self.jitter < 0 or self.pf_sigma <= 0 or self.learning_rate <= 0 or self.train_iters < 0:
            raise ValueError("OfflineConfig: need jitter >= 0, pf_sigma > 0, learning_rate > 0, train_iters >= 0")

    def to_json(self) -> dict:
        """The settings as a JSON-ready dict (``model`` nested as a dict).

        Returns
        -------
        dict
            Field name -> value.
        """
        d = asdict(self)
        d["model"] = asdict(self.model)
        return d


@functools.lru_cache(maxsize=4)
def _compiled(config: OfflineConfig, n_total: int):
    """Optimizer, jitted ELBO step and jitted full filter pass of one configuration."""
    import equinox as eqx
    import jax.numpy as jnp

    from cogmap.genmodel.dvbf import log_likelihood, transition_sample
    from cogmap.inference.chunked_filter import chunked_filter
    from cogmap.inference.elbo import make_optimizer, make_train_step

    cfg = config.model
    opt = make_optimizer(config.learning_rate)
    train_step = make_train_step(cfg, opt, n_total)
    sigma_t = jnp.asarray(cfg.sigma_t)

    @eqx.filter_jit
    def filter_pass(key, particles, us, xs, emission, grid):
        return chunked_filter(key, particles, us, xs, lambda k, z, u: transition_sample(k, z, u, sigma_t),
                              lambda z, x: log_likelihood(emission, grid, z, x, cfg, sigma=config.pf_sigma),
                              chunk=config.chunk, jitter=config.jitter, n_keep=config.cache)

    return opt, train_step, filter_pass


def offline_slam(scans, controls, start, config: OfflineConfig, progress=None, emission=None,
                 round_estimates: list | None = None) -> SLAMResult:
    """Run offline SLAM on ``scans (T, n_beams)`` and ``controls (T - 1, 2)`` from the known ``start``.

    Parameters
    ----------
    scans : array_like, shape (T, n_beams)
        Range scan per step.
    controls : array_like, shape (T - 1, 2)
        Control (turn rad, forward m) leading from step ``t`` to ``t + 1``.
    start : array_like, shape (3,)
        Known initial pose (x m, y m, yaw rad).
    config : OfflineConfig
        Filter and training settings.
    progress : callable, optional
        Called with the number of rounds done after each round.
    emission : optional
        Emission network to start from (for example one pretrained on a first maze).
    round_estimates : list, optional
        If given, each round's estimates ``(T, 3)`` are appended to it.

    Returns
    -------
    SLAMResult
        Per-step estimates and spreads of the last pass, its final particles (the kept ones),
        parameters, losses and run time.

    Raises
    ------
    ValueError
        If there are not exactly ``T - 1`` controls.
    """
    import jax
    import jax.numpy as jnp

    from cogmap.inference.elbo import Batch, init_opt_state, init_params

    scans = np.asarray(scans, float)
    controls = np.asarray(controls, float)
    T = scans.shape[0]
    if controls.shape[0] != T - 1 or T < 2:
        raise ValueError(f"offline_slam: {controls.shape[0]} controls for {T} scans (need T - 1, T >= 2)")
    tic = time.perf_counter()
    cfg = config.model
    key = jax.random.PRNGKey(config.seed)
    key, k_init = jax.random.split(key)
    params = init_params(cfg, k_init)
    if emission is not None:
        params = params._replace(emission=emission)
    opt, train_step, filter_pass = _compiled(config, T)
    opt_state = init_opt_state(opt, params)
    rng = np.random.default_rng(config.seed)
    start = np.asarray(start, float)
    init_std = np.asarray(config.init_std)
    # round 0's cache: path integration, the pose posterior under the prior map
    estimates = path_integration(start, controls)
    spreads = np.zeros_like(estimates)
    cache = np.repeat(estimates[:, None, :], config.cache, axis=1).astype(np.float32)
    cache[0] = start + init_std * rng.standard_normal((config.cache, 3))
    kept_last = cache[-1]
    xs, us = jnp.asarray(scans), jnp.asarray(controls)
    losses = []
    for r in range(config.rounds):
        horizon = int(np.ceil(T * (r + 1) / config.rounds)) if config.grow else T
        for _ in range(config.train_iters):
            idx = rng.integers(0, horizon, config.batch)
            key, k = jax.random.split(key)
            new, opt_state, terms = train_step(params, opt_state, k, Batch(jnp.asarray(cache[idx]), xs[idx]))
            params = new._replace(emission=params.emission) if config.freeze_emission else new
            losses.append(float(terms.loss))
        key, k_part, k_pass = jax.random.split(key, 3)
        particles = jnp.asarray(start) + jnp.asarray(init_std) * jax.random.normal(k_part, (config.n_particles, 3))
        out = filter_pass(k_pass, particles, us, xs[1:], params.emission, params.q_map.mean)
        estimates = np.concatenate([start[None], np.asarray(out.mean)])
        spreads = np.concatenate([init_std[None], np.asarray(out.std)])
        cache[1:] = np.asarray(out.kept)
        kept_last = cache[-1]
        if round_estimates is not None:
            round_estimates.append(estimates.copy())
        if progress is not None:
            progress(r + 1)
    return SLAMResult(estimates, spreads, np.asarray(kept_last), params, np.array(losses),
                      time.perf_counter() - tic)

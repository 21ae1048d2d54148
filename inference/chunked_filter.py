"""The particle filter of DVBF-LM's offline setting (paper Appendix B-I), in JAX.

The traversal is cut into chunks of ``chunk`` consecutive steps, processed in order. At the start of a
chunk the particles are drawn from a **categorical** proposal over the previous step's weighted set
(multinomial resampling, not a moment-matched Normal) and ``jitter`` Gaussian noise is added to each
pose coordinate; inside the chunk they move through the transition without resampling and their log
weights add up the per-step log likelihoods. The paper's settings: chunk 5, jitter 0.001, 1,000
particles, emission std 0.01.

As in :mod:`cogmap.inference.particle_filter` the model enters as two pure functions,
``transition(key, particles (K, D), control) -> (K, D)`` and
``log_likelihood(particles (K, D), observation) -> (K,)``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import jax
import jax.numpy as jnp
from jax.scipy.special import logsumexp


def categorical_resample(key: jax.Array, log_weights: jax.Array, num: int) -> jax.Array:
    """``num`` independent draws of particle indices from normalised ``log_weights (K,)`` by inverse CDF
    (O(K + num log K), unlike ``jax.random.categorical``'s Gumbel draw of a ``(num, K)`` array)."""
    cdf = jnp.cumsum(jnp.exp(log_weights))
    u = jax.random.uniform(key, (num,)) * cdf[-1]
    return jnp.clip(jnp.searchsorted(cdf, u, side="right"), 0, log_weights.shape[0] - 1)


class ChunkedOutput(NamedTuple):
    """Per step of :func:`chunked_filter`: weighted mean and std ``(T, D)``, ``n_keep`` particles
    ``(T, n_keep, D)`` drawn by weight (for the ELBO's cache) and the effective sample size ``(T,)``."""

    mean: jax.Array
    std: jax.Array
    kept: jax.Array
    ess: jax.Array


def chunked_filter(key: jax.Array, particles: jax.Array, controls: jax.Array, observations: jax.Array,
                   transition: Callable, log_likelihood: Callable, chunk: int = 5, jitter: float = 0.001,
                   n_keep: int = 8) -> ChunkedOutput:
    """Filter ``observations (T, ...)`` after ``controls (T, ...)`` (control ``t`` leads to observation
    ``t``) from equally weighted ``particles (K, D)``, resampling only at chunk starts (Appendix B-I).

    Parameters
    ----------
    key : jax.Array
        PRNG key.
    particles : jax.Array, shape (K, D)
        Particles before the first control, equally weighted.
    controls : jax.Array, shape (T, ...)
        Control per step.
    observations : jax.Array, shape (T, ...)
        Observation after each control.
    transition, log_likelihood : callable
        The model (see the module docstring).
    chunk : int
        Steps per chunk; resampling and jitter happen before steps ``0, chunk, 2 chunk, ...``.
    jitter : float
        Std of the Gaussian noise added to every coordinate at a chunk start.
    n_keep : int
        Particles drawn by weight and returned per step.

    Returns
    -------
    ChunkedOutput
        Per-step moments, kept particles and effective sample size.

    Raises
    ------
    ValueError
        If ``chunk < 1`` or ``jitter < 0``.
    """
    if chunk < 1 or jitter < 0:
        raise ValueError(f"chunked_filter: need chunk >= 1 and jitter >= 0, got {chunk}, {jitter}")
    k = particles.shape[0]
    log_w0 = jnp.full((k,), -jnp.log(k))

    def body(carry, inp):
        z, log_w = carry
        t, key_t, u, x = inp
        k_res, k_jit, k_move, k_keep = jax.random.split(key_t, 4)

        def restart(_):
            idx = categorical_resample(k_res, log_w, k)
            return z[idx] + jitter * jax.random.normal(k_jit, z.shape), log_w0

        z, log_w = jax.lax.cond(t % chunk == 0, restart, lambda _: (z, log_w), None)
        z = transition(k_move, z, u)
        log_w = log_w + log_likelihood(z, x)
        log_w = log_w - logsumexp(log_w)
        w = jnp.exp(log_w)
        mean = jnp.sum(w[:, None] * z, 0)
        std = jnp.sqrt(jnp.maximum(jnp.sum(w[:, None] * (z - mean) ** 2, 0), 0.0))
        kept = z[categorical_resample(k_keep, log_w, n_keep)]
        return (z, log_w), (mean, std, kept, 1.0 / jnp.sum(w * w))

    steps = controls.shape[0]
    inputs = (jnp.arange(steps), jax.random.split(key, steps), controls, observations)
    _, (mean, std, kept, ess) = jax.lax.scan(body, (particles, log_w0), inputs)
    return ChunkedOutput(mean, std, kept, ess)

"""Bootstrap particle filter in JAX (Gordon et al. 1993; DVBF-LM pose posterior, paper III-C).

BlackJAX-style: a small state (:class:`ParticleState`), :func:`pf_init`, :func:`pf_step` and
:func:`pf_run` (a ``lax.scan`` over a sequence). The model enters as two pure functions:

* ``transition(key, particles (K, D), control) -> particles (K, D)``, a sample of ``p(z' | z, u)``;
* ``log_likelihood(particles (K, D), observation) -> (K,)``, ``log p(x | z)``.

Every step resamples (systematic resampling) from the previous weights, propagates through the
transition (the proposal of a bootstrap filter) and weights by the likelihood, so the log weights
of a step are the log likelihoods, and ``log mean_k exp(log_w_k)`` estimates ``log p(x_t | x_<t)``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import jax
import jax.numpy as jnp
from jax.scipy.special import logsumexp


class ParticleState(NamedTuple):
    """Particles ``(K, D)``, their normalised log weights ``(K,)`` and ``log p(x_1:t)`` so far."""

    particles: jax.Array
    log_weights: jax.Array
    log_evidence: jax.Array


def systematic_resample(key: jax.Array, weights: jax.Array, num: int | None = None) -> jax.Array:
    """Indices ``(num,)`` drawn by systematic resampling from normalised ``weights (K,)``."""
    n = weights.shape[0] if num is None else num
    u = (jax.random.uniform(key) + jnp.arange(n)) / n
    cdf = jnp.cumsum(weights)
    cdf = cdf / cdf[-1]
    return jnp.clip(jnp.searchsorted(cdf, u, side="right"), 0, weights.shape[0] - 1)


def normalise_log_weights(log_w: jax.Array) -> tuple[jax.Array, jax.Array]:
    """Normalised log weights and ``log mean exp`` of the raw ones (the step's evidence)."""
    lse = logsumexp(log_w)
    return log_w - lse, lse - jnp.log(log_w.shape[0])


def pf_init(particles: jax.Array, observation=None, log_likelihood: Callable | None = None) -> ParticleState:
    """State from initial particles; weighted by the first observation when one is given."""
    k = particles.shape[0]
    if observation is None:
        # weights typed as the particles (not weakly typed): a compiled filter sees the same types at every step
        return ParticleState(particles, jnp.full((k,), -jnp.log(k), particles.dtype), jnp.zeros(()))
    log_w, log_z = normalise_log_weights(log_likelihood(particles, observation))
    return ParticleState(particles, log_w, log_z)


def pf_step(key: jax.Array, state: ParticleState, control, observation, transition: Callable,
            log_likelihood: Callable) -> tuple[ParticleState, jax.Array]:
    """Resample, propagate with ``control``, weight by ``observation``; returns the state and
    ``log p(x_t | x_<t)``."""
    k_res, k_move = jax.random.split(key)
    idx = systematic_resample(k_res, jnp.exp(state.log_weights))
    moved = transition(k_move, state.particles[idx], control)
    log_w, log_z = normalise_log_weights(log_likelihood(moved, observation))
    return ParticleState(moved, log_w, state.log_evidence + log_z), log_z


def weighted_moments(state: ParticleState) -> tuple[jax.Array, jax.Array]:
    """Weighted mean and standard deviation ``(D,)`` of the particles."""
    w = jnp.exp(state.log_weights)[:, None]
    mean = jnp.sum(w * state.particles, 0)
    return mean, jnp.sqrt(jnp.maximum(jnp.sum(w * (state.particles - mean) ** 2, 0), 0.0))


def pf_run(key: jax.Array, state: ParticleState, controls: jax.Array, observations: jax.Array,
           transition: Callable, log_likelihood: Callable, record: Callable | None = None):
    """Filter ``observations (T, ...)`` after ``controls (T, ...)`` (control t leads to observation t)
    in one ``lax.scan``; step t uses the t-th key of ``jax.random.split(key, T)``.

    Returns the final state and per-step ``(mean (T, D), std (T, D), log_z (T,))``, or, with
    ``record(key_t, state_t) -> pytree``, what ``record`` returns at each step, stacked (the online
    SLAM keeps a sample of the particles and their moments this way).
    """

    def body(s, inp):
        k, u, x = inp
        s, log_z = pf_step(k, s, u, x, transition, log_likelihood)
        if record is not None:
            return s, record(k, s)
        mean, std = weighted_moments(s)
        return s, (mean, std, log_z)

    keys = jax.random.split(key, controls.shape[0])
    return jax.lax.scan(body, state, (keys, controls, observations))

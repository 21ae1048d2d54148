"""The bootstrap particle filter as a registered inference scheme (name ``"particle_filter"``).

Same call as every scheme: ``posterior, info = scheme(model, prior, observations, actions=None, **options)``,
for continuous-state models:

* ``model``: a :class:`ParticleModel` with ``transition(key, particles (K, D), control)`` and
  ``log_likelihood(particles (K, D), observation) -> (K,)`` (pure JAX functions);
* ``prior``: initial particles ``(K, D)``, or ``(mean, std)`` from which ``num_particles`` are drawn;
* ``observations``: ``T`` observations (array ``(T, ...)``); ``actions``: ``T - 1`` controls.

``posterior`` is ``(particles (K, D), weights (K,))`` at the last step; ``info.history`` holds one
``(mean, std)`` pair per step, ``info.free_energy`` is ``-log p(x_T | x_<T)`` and
``info.total_free_energy`` ``-log p(x_1:T)`` (the filter's unbiased estimates, in log space).
jax is imported when the scheme is called, not when :mod:`cogmap.inference` is imported.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np

from .base import InferenceError, InferenceInfo


class ParticleModel(NamedTuple):
    """A continuous-state model for the ``"particle_filter"`` scheme (two pure JAX functions).

    Attributes
    ----------
    transition : callable
        ``transition(key, particles (K, D), control) -> (K, D)`` samples the next particles.
    log_likelihood : callable
        ``log_likelihood(particles (K, D), observation) -> (K,)`` log-likelihood of each particle.
    """
    transition: Callable
    log_likelihood: Callable


def particle_filter(model, prior, observations, actions=None, *, num_particles: int = 1000, seed: int = 0):
    """Bootstrap particle filter as an inference scheme (jax is imported on the first call).

    Parameters
    ----------
    model : ParticleModel
        Transition sampler and log-likelihood.
    prior : numpy.ndarray or tuple
        Initial particles ``(K, D)``, or ``(mean, std)`` (each ``(D,)``) from which ``num_particles``
        are drawn.
    observations : array_like
        ``(T, ...)`` float, ``T >= 1`` observations.
    actions : array_like, optional
        ``(T - 1, ...)`` controls; required when ``T > 1``.
    num_particles : int, optional
        Particles drawn from a ``(mean, std)`` prior, default 1000.
    seed : int, optional
        Seed of the JAX random key, default 0.

    Returns
    -------
    posterior : tuple of numpy.ndarray
        ``(particles (K, D), weights (K,))`` at the last step.
    info : InferenceInfo
        ``history`` holds one ``(mean, std)`` pair per step, ``free_energy`` is the estimate of
        ``-log p(x_T | x_<T)`` and ``total_free_energy`` of ``-log p(x_1:T)``.

    Raises
    ------
    InferenceError
        For a model of another type, empty observations, a malformed prior, or a wrong number of
        actions.
    """
    if not isinstance(model, ParticleModel):
        raise InferenceError("particle_filter: model must be a ParticleModel(transition, log_likelihood)")
    import jax
    import jax.numpy as jnp

    from .particle_filter import pf_init, pf_run, weighted_moments

    obs = jnp.asarray(np.asarray(observations, float))
    if obs.ndim < 1 or obs.shape[0] < 1:
        raise InferenceError("particle_filter: observations must be a non-empty sequence")
    T = obs.shape[0]
    key = jax.random.PRNGKey(seed)
    k0, key = jax.random.split(key)
    if isinstance(prior, tuple | list) and len(prior) == 2:
        mean, std = (np.atleast_1d(np.asarray(v, float)) for v in prior)
        if mean.shape != std.shape or np.any(std < 0):
            raise InferenceError("particle_filter: prior (mean, std) must have equal shapes and std >= 0")
        particles = jnp.asarray(mean) + jnp.asarray(std) * jax.random.normal(k0, (num_particles, mean.shape[0]))
    else:
        particles = jnp.asarray(np.asarray(prior, float))
        if particles.ndim != 2:
            raise InferenceError(f"particle_filter: prior particles must be (K, D), got shape {particles.shape}")
    if actions is None:
        if T > 1:
            raise InferenceError("particle_filter: T > 1 observations need T - 1 actions")
        acts = jnp.zeros((0, 1))
    else:
        acts = jnp.asarray(np.asarray(actions, float))
        if acts.shape[0] != T - 1:
            raise InferenceError(f"particle_filter: got {acts.shape[0]} actions for {T} observations (need T - 1)")
    state = pf_init(particles, obs[0], model.log_likelihood)
    m0, s0 = weighted_moments(state)
    log_z = [float(state.log_evidence)]
    means, stds = [np.asarray(m0)], [np.asarray(s0)]
    if T > 1:
        state, (m, s, lz) = pf_run(key, state, acts, obs[1:], model.transition, model.log_likelihood)
        means += list(np.asarray(m))
        stds += list(np.asarray(s))
        log_z += np.asarray(lz).tolist()
    posterior = (np.asarray(state.particles), np.exp(np.asarray(state.log_weights)))
    history = tuple(zip(means, stds, strict=True))
    return posterior, InferenceInfo(free_energy=-log_z[-1], history=history, iterations=1,
                                    total_free_energy=-float(np.sum(log_z)))

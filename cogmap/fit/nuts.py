"""The full posterior of free parameters by NUTS (blackjax), per subject or with group-level priors.

blackjax is used because it is a library of pure ``init``/``step`` kernels over JAX pytrees, like
this toolkit's agents: the log density is our jitted likelihood plus the priors, adaptation is
Stan's window adaptation, and chains of all subjects run in one ``vmap``. (numpyro would ask for
the agent to be rewritten as a numpyro model with ``sample`` sites; the likelihood here is
already a plain function.)

* ``hierarchical=False``: every subject's parameters have the priors of their :class:`Free`;
  the subjects' posteriors are independent and sampled side by side.
* ``hierarchical=True``: ``theta_i = mu + sigma * z_i`` (non-centred) with ``z_i ~ N(0, 1)``,
  ``mu`` drawn from the priors of the :class:`Free` parameters and ``log sigma ~ N(log(prior
  spread / 2), 1)``: one joint posterior over the group and every subject.

Diagnostics (split R-hat, effective sample size) come from
:mod:`cogmap.inference.mcmc_diagnostics`.
"""

from __future__ import annotations

from functools import partial
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from cogmap.inference.mcmc_diagnostics import effective_sample_size, split_rhat
from cogmap.jax_agent import Agent

from .likelihood import Behaviour, apply, check_free, log_likelihood, log_posterior, values


class PosteriorResult(NamedTuple):
    """Posterior draws and their summaries.

    Attributes
    ----------
    names : tuple of str
        Free parameter names (the last axis).
    draws : numpy.ndarray
        ``(chains, samples, N, k)`` float draws on the natural scale.
    mean, sd, q05, q95 : numpy.ndarray
        ``(N, k)`` float posterior mean, standard deviation and 5 % / 95 % quantiles per subject.
    rhat : numpy.ndarray
        ``(N, k)`` float split R-hat.
    ess : numpy.ndarray
        ``(N, k)`` float effective sample size.
    group : dict or None
        Hierarchical fits: ``{"mu": (chains, samples, k), "sigma": (chains, samples, k)}`` draws of
        the group mean and spread on the unconstrained scale; None otherwise.
    """

    names: tuple
    draws: np.ndarray
    mean: np.ndarray
    sd: np.ndarray
    q05: np.ndarray
    q95: np.ndarray
    rhat: np.ndarray
    ess: np.ndarray
    group: dict | None = None


def _sample(logdensity, key, position, warmup: int, samples: int):
    """Window adaptation then ``samples`` NUTS draws of one chain."""
    import blackjax

    k_warm, k_draw = jax.random.split(key)
    adapt = blackjax.window_adaptation(blackjax.nuts, logdensity)
    (state, parameters), _ = adapt.run(k_warm, position, num_steps=warmup)
    kernel = blackjax.nuts(logdensity, **parameters).step

    def one(state, k):
        state, _ = kernel(k, state)
        return state, state.position

    _, positions = jax.lax.scan(one, state, jax.random.split(k_draw, samples))
    return positions


def _summary(names, draws, group=None) -> PosteriorResult:
    c, s, n, k = draws.shape
    flat = draws.reshape(c * s, n, k)
    rhat = np.stack([split_rhat(draws[:, :, i, :]) for i in range(n)])
    ess = np.stack([effective_sample_size(draws[:, :, i, :]) for i in range(n)])
    return PosteriorResult(names, draws, flat.mean(axis=0), flat.std(axis=0, ddof=1),
                           np.quantile(flat, 0.05, axis=0), np.quantile(flat, 0.95, axis=0), rhat, ess, group)


def fit_nuts(agent: Agent, free, data: Behaviour, key, *, chains: int = 2, warmup: int = 300, samples: int = 300,
             hierarchical: bool = False) -> PosteriorResult:
    """Posterior draws of the free parameters of every subject by NUTS.

    Parameters
    ----------
    agent : Agent
    free : sequence of Free
    data : Behaviour
        Subjects stacked on a leading axis (``actions`` shaped ``(N, K, T, F)``).
    key : jax.Array
        Random key.
    chains : int, optional
        Chains per subject (or of the joint posterior), default 2 (at least 2 for R-hat).
    warmup, samples : int, optional
        Adaptation steps and kept draws per chain, default 300 each.
    hierarchical : bool, optional
        Group-level priors (see the module docstring), default False.

    Returns
    -------
    PosteriorResult

    Raises
    ------
    ValueError
        For bad free parameters, data without a subject axis, fewer than 2 chains or fewer than
        4 samples.
    """
    free = check_free(free, agent)
    if np.ndim(data.actions) != 4:
        raise ValueError(f"fit_nuts needs subjects stacked: actions shaped (N, trials, steps, factors), "
                         f"got {np.shape(data.actions)}")
    if chains < 2 or samples < 4 or warmup < 1:
        raise ValueError(f"need chains >= 2, samples >= 4 and warmup >= 1; got {chains}, {samples}, {warmup}")
    names = tuple(f.name for f in free)
    keys = jax.random.split(key, chains)
    theta, group = _run(agent.config, free, int(warmup), int(samples), bool(hierarchical), agent.params, data, keys)
    if group is None:
        theta = jnp.moveaxis(theta, 0, 2)  # (N, chains, samples, k) -> (chains, samples, N, k)
    draws = np.asarray(values(free, jnp.moveaxis(theta, -1, 0))).transpose(1, 2, 3, 0)
    return _summary(names, draws, None if group is None else {k: np.asarray(v) for k, v in group.items()})


@partial(jax.jit, static_argnums=(0, 1, 2, 3, 4))
def _run(config, free, warmup, samples, hierarchical, params, data, keys):
    """The chains (jitted once per config, free parameters, settings and data shapes)."""
    agent = Agent(config, params)
    N, k = data.actions.shape[0], len(free)
    dt = params.gamma.dtype
    centre = jnp.stack([jnp.asarray(f.prior[0], dtype=dt) for f in free])
    if not hierarchical:
        def chain(subject, kk):
            return _sample(lambda th: log_posterior(agent, free, th, subject), kk, centre, warmup, samples)

        return jax.vmap(jax.vmap(chain, in_axes=(None, 0)), in_axes=(0, None))(data, keys), None

    spread = jnp.stack([jnp.asarray(f.prior[1], dtype=dt) for f in free])

    def logdensity(pos):
        sigma = jnp.exp(pos["log_sigma"])
        theta = pos["mu"] + sigma * pos["z"]  # (N, k)
        ll = jnp.sum(jax.vmap(lambda th, s: log_likelihood(agent, s, apply(params, free, th)))(theta, data))
        lp = -0.5 * jnp.sum(pos["z"] ** 2) - 0.5 * jnp.sum(((pos["mu"] - centre) / spread) ** 2)
        lp = lp - 0.5 * jnp.sum((pos["log_sigma"] - jnp.log(spread / 2)) ** 2)
        return ll + lp

    start = {"mu": centre, "log_sigma": jnp.log(spread / 2), "z": jnp.zeros((N, k), dtype=dt)}
    pos = jax.vmap(lambda kk: _sample(logdensity, kk, start, warmup, samples))(keys)
    theta = pos["mu"][:, :, None, :] + jnp.exp(pos["log_sigma"])[:, :, None, :] * pos["z"]  # (c, s, N, k)
    return theta, {"mu": pos["mu"], "sigma": jnp.exp(pos["log_sigma"])}


__all__ = ["PosteriorResult", "fit_nuts"]

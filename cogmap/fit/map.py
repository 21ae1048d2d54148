"""Maximum a posteriori estimates of free parameters, for every subject at once (Adam from optax)."""

from __future__ import annotations

from functools import partial
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from cogmap.jax_agent import Agent

from .likelihood import Behaviour, check_free, log_posterior, unconstrained, values


class MAPResult(NamedTuple):
    """Maximum a posteriori estimates (one row per subject).

    Attributes
    ----------
    names : tuple of str
        Free parameter names, in column order.
    values : numpy.ndarray
        ``(N, k)`` float estimates on the natural scale.
    theta : numpy.ndarray
        ``(N, k)`` float estimates on the unconstrained scale.
    log_posterior : numpy.ndarray
        ``(N,)`` float ``log p(choices | theta) + log p(theta)`` at the estimate.
    trace : numpy.ndarray
        ``(iterations, N)`` float negative log posterior per iteration (convergence).
    """

    names: tuple
    values: np.ndarray
    theta: np.ndarray
    log_posterior: np.ndarray
    trace: np.ndarray


def fit_map(agent: Agent, free, data: Behaviour, *, iterations: int = 300, learning_rate: float = 0.05,
            init=None) -> MAPResult:
    """MAP estimates of the free parameters for every subject at once (Adam, from optax).

    Parameters
    ----------
    agent : Agent
    free : sequence of Free
    data : Behaviour
        Subjects stacked on a leading axis (``actions`` shaped ``(N, K, T, F)``).
    iterations : int, optional
        Adam steps, default 300.
    learning_rate : float, optional
        Adam step size on the unconstrained scale, default 0.05.
    init : array_like, optional
        ``(k,)`` starting values on the natural scale; default the priors' centres.

    Returns
    -------
    MAPResult

    Raises
    ------
    ValueError
        For bad free parameters (:func:`check_free`), data without a subject axis, or
        ``iterations < 1``.
    """
    free = check_free(free, agent)
    if np.ndim(data.actions) != 4:
        raise ValueError(f"fit_map needs subjects stacked: actions shaped (N, trials, steps, factors), "
                         f"got {np.shape(data.actions)}")
    if iterations < 1:
        raise ValueError(f"iterations must be >= 1, got {iterations}")
    start = (jnp.stack([f.prior[0] for f in free]) if init is None else unconstrained(free, init))
    start = start.astype(agent.params.gamma.dtype)
    theta, lp, trace = _run(agent.config, free, int(iterations), float(learning_rate), agent.params, start, data)
    return MAPResult(tuple(f.name for f in free), np.asarray(values(free, theta.T).T), np.asarray(theta),
                     np.asarray(lp), np.asarray(trace).T)


@partial(jax.jit, static_argnums=(0, 1, 2, 3))
def _run(config, free, iterations, learning_rate, params, start, data):
    """Adam on every subject at once (jitted once per config, free parameters and data shapes)."""
    import optax

    agent = Agent(config, params)
    opt = optax.adam(learning_rate)

    def one(subject):
        loss = lambda th: -log_posterior(agent, free, th, subject)  # noqa: E731
        grad = jax.value_and_grad(loss)

        def body(carry, _):
            th, st = carry
            value, g = grad(th)
            upd, st = opt.update(g, st, th)
            return (optax.apply_updates(th, upd), st), value

        (th, _), trace = jax.lax.scan(body, (start, opt.init(start)), None, length=iterations)
        return th, -loss(th), trace

    return jax.vmap(one)(data)


__all__ = ["MAPResult", "fit_map"]

"""Bayesian model comparison between candidate agents on the same behaviour (Laplace log evidence).

For each subject and candidate, the log evidence ``log p(choices | candidate)`` is approximated
around the MAP estimate (Laplace's method, as SPM's variational Laplace reports it):

``log p(y) ~ log p(y | theta*) + log p(theta*) + k/2 log(2 pi) - 1/2 log det H``

with ``H`` the Hessian of the negative log posterior at ``theta*`` (computed by ``jax.hessian``).
The candidate with the highest evidence wins a subject; summed over subjects it is the fixed-
effects group comparison. :func:`confusion` simulates subjects from each candidate and counts
which candidate wins them (model recovery).
"""

from __future__ import annotations

from functools import partial
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from cogmap.jax_agent import Agent

from .likelihood import Behaviour, apply, check_free, log_posterior, simulate, unconstrained
from .map import fit_map


class Candidate(NamedTuple):
    """A candidate agent and its free parameters.

    Attributes
    ----------
    name : str
        Label in tables.
    agent : Agent
        The agent (its parameters are the fixed values of everything not free).
    free : tuple of Free
        Its free parameters.
    """

    name: str
    agent: Agent
    free: tuple


class Comparison(NamedTuple):
    """Log evidence of every candidate for every subject.

    Attributes
    ----------
    names : tuple of str
        Candidate names (columns).
    log_evidence : numpy.ndarray
        ``(N, C)`` float, nats.
    winner : numpy.ndarray
        ``(N,)`` int column of the best candidate per subject.
    total : numpy.ndarray
        ``(C,)`` float log evidence summed over subjects (fixed effects).
    """

    names: tuple
    log_evidence: np.ndarray
    winner: np.ndarray
    total: np.ndarray


def laplace_evidence(agent: Agent, free, data: Behaviour, *, iterations: int = 300) -> np.ndarray:
    """Laplace approximation of ``log p(choices)`` of every subject under one candidate.

    Parameters
    ----------
    agent : Agent
    free : sequence of Free
    data : Behaviour
        Subjects stacked on a leading axis.
    iterations : int, optional
        Adam steps of the MAP fit, default 300.

    Returns
    -------
    numpy.ndarray
        ``(N,)`` float, nats (``-inf`` where the Hessian is not positive definite).
    """
    free = check_free(free, agent)
    res = fit_map(agent, free, data, iterations=iterations)
    return np.asarray(_laplace(agent.config, free, agent.params, jnp.asarray(res.theta), data))


@partial(jax.jit, static_argnums=(0, 1))
def _laplace(config, free, params, theta, data):
    agent = Agent(config, params)
    k = len(free)

    def one(th, subject):
        neg = lambda x: -log_posterior(agent, free, x, subject)  # noqa: E731
        H = jax.hessian(neg)(th)
        sign, logdet = jnp.linalg.slogdet(H)
        z = -neg(th) + 0.5 * k * jnp.log(2 * jnp.pi) - 0.5 * logdet
        return jnp.where(sign > 0, z, -jnp.inf)

    return jax.vmap(one)(theta, data)


def compare(candidates, data: Behaviour, *, iterations: int = 300) -> Comparison:
    """Compare candidate agents on the same subjects by Laplace log evidence.

    Parameters
    ----------
    candidates : sequence of Candidate
        At least two, with distinct names.
    data : Behaviour
        Subjects stacked on a leading axis.
    iterations : int, optional
        Adam steps of each MAP fit.

    Returns
    -------
    Comparison

    Raises
    ------
    ValueError
        For fewer than two candidates or repeated names.
    """
    candidates = tuple(candidates)
    names = tuple(c.name for c in candidates)
    if len(candidates) < 2 or len(set(names)) != len(names):
        raise ValueError(f"compare needs at least two candidates with distinct names, got {list(names)}")
    ev = np.stack([laplace_evidence(c.agent, c.free, data, iterations=iterations) for c in candidates], axis=1)
    return Comparison(names, ev, np.argmax(ev, axis=1), ev.sum(axis=0))


def simulate_subjects(candidate: Candidate, world, key, values, *, trials: int, steps: int) -> Behaviour:
    """Behaviour of subjects of ``candidate`` with the given free-parameter ``values`` (``(N, k)``, natural scale).

    Parameters
    ----------
    candidate : Candidate
    world : cogmap.envs.jax_worlds.World
    key : jax.Array
    values : array_like
        ``(N, k)`` true parameter values per subject.
    trials, steps : int
        Trials per subject and steps per trial.

    Returns
    -------
    Behaviour
        Subjects stacked on a leading axis.
    """
    free = check_free(candidate.free, candidate.agent)
    agent = candidate.agent
    v = jnp.asarray(values, dtype=agent.params.gamma.dtype)
    return _simulate(agent.config, free, world.layout, int(trials), int(steps), agent.params, world.arrays, v, key)


@partial(jax.jit, static_argnums=(0, 1, 2, 3, 4))
def _simulate(config, free, world_layout, trials, steps, params, world_arrays, vals, key):
    from cogmap.envs.jax_worlds import World

    agent, world = Agent(config, params), World(world_layout, world_arrays)
    theta = jax.vmap(lambda v: unconstrained(free, v))(vals)

    def one(th, k):
        return simulate(agent, world, k, trials, steps, apply(agent.params, free, th))

    return jax.vmap(one)(theta, jax.random.split(key, theta.shape[0]))


def confusion(candidates, world, key, values_of, *, subjects: int, trials: int, steps: int,
              iterations: int = 300) -> np.ndarray:
    """Model recovery: ``M[i, j]`` = share of subjects simulated by candidate ``i`` that ``j`` wins.

    Parameters
    ----------
    candidates : sequence of Candidate
    world : cogmap.envs.jax_worlds.World
    key : jax.Array
    values_of : callable
        ``values_of(i, rng) -> (subjects, k_i)`` true parameter values for candidate ``i``
        (``rng`` a numpy Generator).
    subjects, trials, steps : int
        Simulated subjects per candidate, trials per subject, steps per trial.
    iterations : int, optional
        Adam steps of each MAP fit.

    Returns
    -------
    numpy.ndarray
        ``(C, C)`` float, rows sum to 1.
    """
    candidates = tuple(candidates)
    rng = np.random.default_rng(int(jax.random.randint(key, (), 0, 2**31 - 1)))
    out = np.zeros((len(candidates), len(candidates)))
    for i, (cand, k) in enumerate(zip(candidates, jax.random.split(key, len(candidates)), strict=True)):
        data = simulate_subjects(cand, world, k, values_of(i, rng), trials=trials, steps=steps)
        winner = compare(candidates, data, iterations=iterations).winner
        out[i] = np.bincount(winner, minlength=len(candidates)) / subjects
    return out


__all__ = ["Candidate", "Comparison", "compare", "confusion", "laplace_evidence", "simulate_subjects"]

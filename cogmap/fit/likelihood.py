"""The likelihood of observed choices under an agent, and free parameters with priors.

    agent = jax_agent.build(tmaze_model(), policy_len=2, gamma=4.0)
    free = [fit.Free("gamma", prior=fit.LogNormal(1.0, 0.5))]
    data = fit.simulate(agent, world, key, trials=100, steps=3)            # one subject
    fit.log_likelihood(agent, data)                                          # log p(actions | obs, params)
    result = fit.fit_map(agent, free, subjects)                              # every subject at once

A subject's data (:class:`Behaviour`) is what it saw and what it chose, trial by trial. The
likelihood runs the agent through each trial with the subject's choices in place of its own
(``action=`` of :func:`cogmap.jax_agent.step`) and sums ``log action_probs[choice]``: the
probability the agent gave to what the subject did. Trials start from the prior ``D``; an agent
that learns carries its learnt arrays from one trial to the next. Everything is a pure JAX
function of the parameters: ``jax.grad`` gives its gradient, ``jax.vmap`` runs many subjects.

Free parameters (:class:`Free`) are named, live on an unconstrained scale (log for positive
quantities) and carry a prior on that scale; :func:`apply` writes values into
:class:`~cogmap.jax_agent.AgentParams`:

``gamma``  policy precision (positive) · ``alpha``  action precision (positive) · ``lr_A``,
``lr_B``  learning rates (positive) ·
``C:<m>``  scale of the log-preferences of modality ``m`` (an index) · ``pA:<m>``  scale of the
Dirichlet counts of ``A[m]`` (positive) · ``w:<term>``  the weight of an EFE term of
:class:`~cogmap.planning.jax_efe.EFEWeights` (e.g. ``w:state_info_gain``).
"""

from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp

from cogmap.jax_agent import Agent, AgentParams
from cogmap.jax_agent import rollout as _rollout
from cogmap.planning.jax_efe import EFEWeights


class Behaviour(NamedTuple):
    """What one subject saw and chose (stack a leading axis for many subjects).

    Attributes
    ----------
    obs : tuple of jax.Array
        Per modality ``(K, T, obs_capacity[m])`` observation vectors, ``K`` trials of ``T`` steps.
    actions : jax.Array
        ``(K, T, F)`` int controls the subject chose after each observation.
    """

    obs: tuple
    actions: jax.Array


class Normal(NamedTuple):
    """Normal prior on the unconstrained value (for a parameter with the identity transform)."""

    mean: float = 0.0
    sd: float = 1.0


class LogNormal(NamedTuple):
    """Prior whose log is Normal(``log_mean``, ``log_sd``) (for a positive parameter)."""

    log_mean: float = 0.0
    log_sd: float = 1.0


class Free(NamedTuple):
    """A free parameter: its name (see the module docstring) and its prior.

    Attributes
    ----------
    name : str
        ``gamma``, ``alpha``, ``lr_A``, ``lr_B``, ``C:<m>``, ``pA:<m>`` or ``w:<term>``.
    prior : Normal or LogNormal
        Prior of the value (LogNormal for the positive ones, Normal for ``C:`` and ``w:``).
    """

    name: str
    prior: Normal | LogNormal = LogNormal()


_SCALARS = ("gamma", "alpha", "lr_A", "lr_B")  # fields of AgentParams
_POSITIVE = (*_SCALARS, "pA")


def _kind(name: str) -> tuple[str, str | None]:
    head, _, tail = name.partition(":")
    if head in _SCALARS and not tail:
        return head, None
    if head in ("C", "pA") and tail.isdigit():
        return head, tail
    if head == "w" and tail in EFEWeights._fields:
        return head, tail
    raise ValueError(f"unknown free parameter {name!r} (known: gamma, alpha, lr_A, lr_B, C:<modality>, pA:<modality>, "
                     f"w:<{'|'.join(EFEWeights._fields)}>)")


def check_free(free, agent: Agent) -> tuple[Free, ...]:
    """Validate free parameters against an agent: known names, matching priors, existing modalities.

    Parameters
    ----------
    free : sequence of Free
    agent : Agent

    Returns
    -------
    tuple of Free

    Raises
    ------
    ValueError
        For an unknown or repeated name, a modality out of range, counts that do not exist, or a
        prior that does not fit the parameter's scale.
    """
    free = tuple(free)
    if not free:
        raise ValueError("no free parameters given")
    names = [f.name for f in free]
    if len(set(names)) != len(names):
        raise ValueError(f"free parameters repeat a name: {names}")
    M = agent.config.layout.num_modalities
    for f in free:
        head, tail = _kind(f.name)
        if head in ("C", "pA") and int(tail) >= M:
            raise ValueError(f"{f.name}: the model has {M} modalities")
        if head == "pA" and agent.params.arrays.pA[int(tail)] is None:
            raise ValueError(f"{f.name}: modality {tail} has no Dirichlet counts")
        want = LogNormal if head in _POSITIVE else Normal
        if not isinstance(f.prior, want):
            raise ValueError(f"{f.name}: needs a {want.__name__} prior, got {type(f.prior).__name__}")
        if not f.prior[1] > 0:
            raise ValueError(f"{f.name}: the prior's spread must be positive, got {f.prior[1]}")
    return free


def values(free, theta):
    """Parameter values from unconstrained ``theta`` (``exp`` for the positive ones)."""
    return jnp.stack([jnp.exp(theta[i]) if _kind(f.name)[0] in _POSITIVE else theta[i] for i, f in enumerate(free)])


def unconstrained(free, value):
    """The inverse of :func:`values`."""
    value = jnp.asarray(value)
    return jnp.stack([jnp.log(value[i]) if _kind(f.name)[0] in _POSITIVE else value[i] for i, f in enumerate(free)])


def apply(params: AgentParams, free, theta) -> AgentParams:
    """``params`` with the free parameters set from unconstrained ``theta`` (``(k,)``).

    ``C:<m>`` and ``pA:<m>`` multiply the agent's own ``C[m]`` and ``pA[m]``.
    """
    vals = values(free, theta)
    arrays, weights = params.arrays, params.weights
    for f, v in zip(free, vals, strict=True):
        head, tail = _kind(f.name)
        if head in _SCALARS:
            params = params._replace(**{head: v})
        elif head == "C":
            m = int(tail)
            arrays = arrays._replace(C=tuple(c * v if i == m else c for i, c in enumerate(arrays.C)))
        elif head == "pA":
            m = int(tail)
            arrays = arrays._replace(pA=tuple(p * v if i == m else p for i, p in enumerate(arrays.pA)))
        else:
            weights = weights._replace(**{tail: v})
    return params._replace(arrays=arrays, weights=weights)


def log_prior(free, theta):
    """Log density of the priors at unconstrained ``theta`` (on that scale)."""
    total = 0.0
    for i, f in enumerate(free):
        mu, sd = f.prior
        total = total - 0.5 * ((theta[i] - mu) / sd) ** 2 - jnp.log(sd) - 0.5 * jnp.log(2 * jnp.pi)
    return total


def _trial(agent: Agent, params: AgentParams, obs, actions):
    """``(log p(choices of one trial), params after it)``."""
    state = agent.init(jax.random.key(0), params)

    def body(state, x):
        o, a = x
        state, info = agent.step(state, o, a)
        p = info.action_probs[tuple(a[f] for f in range(a.shape[0]))]
        return state, jnp.log(jnp.maximum(p, 1e-300))

    state, lp = jax.lax.scan(body, state, (obs, actions))
    return jnp.sum(lp), state.params


def log_likelihood(agent: Agent, data: Behaviour, params: AgentParams | None = None):
    """``log p(choices | observations, params)`` of one subject, summed over trials and steps.

    Parameters
    ----------
    agent : Agent
    data : Behaviour
        One subject (``actions`` shaped ``(K, T, F)``).
    params : AgentParams, optional
        Default the agent's.

    Returns
    -------
    jax.Array
        Scalar, nats.
    """
    params = agent.params if params is None else params
    learns = agent.config.learn_A or agent.config.learn_B
    if not learns:
        lp, _ = jax.vmap(lambda o, a: _trial(agent, params, o, a))(data.obs, data.actions)
        return jnp.sum(lp)

    def body(p, x):
        lp, p = _trial(agent, p, *x)
        return p, lp

    _, lp = jax.lax.scan(body, params, (data.obs, data.actions))
    return jnp.sum(lp)


def simulate(agent: Agent, world, key, trials: int, steps: int, params: AgentParams | None = None) -> Behaviour:
    """A subject's behaviour: ``trials`` episodes of ``steps`` steps against ``world`` (learning
    carried across trials when the agent learns).

    Parameters
    ----------
    agent : Agent
    world : cogmap.envs.jax_worlds.World
    key : jax.Array
    trials, steps : int
    params : AgentParams, optional
        The subject's parameters (default the agent's).

    Returns
    -------
    Behaviour
    """
    params = agent.params if params is None else params

    def body(p, k):
        tr = _rollout(agent, world, k, steps, p)
        return (tr.state.params if agent.config.learn_A or agent.config.learn_B else p), (tr.obs, tr.actions)

    _, (obs, actions) = jax.lax.scan(body, params, jax.random.split(key, trials))
    return Behaviour(obs, actions)


def log_posterior(agent: Agent, free, theta, data: Behaviour):
    """``log p(choices | theta) + log p(theta)`` of one subject (unnormalised)."""
    return log_likelihood(agent, data, apply(agent.params, free, theta)) + log_prior(free, theta)


__all__ = ["Behaviour", "Free", "LogNormal", "Normal", "apply", "check_free", "log_likelihood", "log_posterior",
           "log_prior", "simulate", "unconstrained", "values"]

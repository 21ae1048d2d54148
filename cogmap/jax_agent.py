"""The agent loop of :mod:`cogmap.loop` on the JAX backend: pure ``init``/``step`` to jit, vmap and differentiate.

    agent = jax_agent.build(tmaze(), policy_len=2, gamma=16.0)
    state = agent.init(jax.random.key(0))
    state, info = jax.jit(agent.step)(state, obs)            # obs: one vector per modality
    states = jax.vmap(agent.init)(jax.random.split(key, 4096))
    states, infos = jax.jit(jax.vmap(agent.step))(states, batch_obs)   # 4096 agents in one call

One ``step`` does what :func:`cogmap.loop.step` does: infer the state posterior with the named
scheme, learn ``A`` and ``B`` when asked (Eq. 8 of the AIMAPP paper), evaluate every policy by
expected free energy, and choose the next control, then predict the next prior through ``B``.
It also reports ``action_probs``, the probability of every control combination it could take
(what it samples from, with habits ``E``, action precision ``alpha`` and the sampling mode of
:mod:`cogmap.planning.action_selection`), and takes
``action=`` to use a given control (a subject's choice) in place of its own: the log-probability
of a subject's choices is the sum of ``log action_probs[choice]`` over trials
(:func:`cogmap.fit.log_likelihood`).

Everything that can be fitted or batched is an array in :class:`AgentParams` (the model arrays,
``gamma``, the EFE weights, the learning rates, the log habits, ``alpha``); the rest is the
static :class:`JaxConfig`,
hashed into the jit cache.
"""

from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from cogmap.genmodel import Model, SpecError
from cogmap.genmodel.jax_model import JaxModel, Layout, to_jax
from cogmap.inference import jax_schemes as js
from cogmap.planning import efe
from cogmap.planning import jax_efe as je
from cogmap.planning.action_selection import check_habits, check_selection
from cogmap.planning.decide import check_plan_settings
from cogmap.planning.policies import enumerate_policies


class JaxConfig(NamedTuple):
    """Static settings (hashable: a change recompiles).

    Attributes
    ----------
    layout : Layout
        The model's structure.
    scheme : str
        One of ``jax_schemes.SCHEMES``.
    num_iter : int
        Sweeps of the iterative schemes.
    tau : float
        Step size of ``vmp_pymdp`` / ``mmp``.
    policies : tuple
        ``(P, T, F)`` nested tuple of int: the enumerated policies.
    learn_A, learn_B : bool
        Whether to learn the likelihood / the transitions.
    sample : bool
        Sample the action from ``q(pi)`` (False: take the policy of highest probability).
    tol : float or None
        Early stop of fpi and vmp (``jax_schemes.fpi``, ``jax_schemes.vmp``); None: always
        ``num_iter`` sweeps.
    sampling : str
        ``"policy"`` or ``"marginal"`` (:mod:`cogmap.planning.action_selection`).
    """

    layout: Layout
    scheme: str = "fpi"
    num_iter: int = 16
    tau: float = 1.0
    policies: tuple = ()
    learn_A: bool = False
    learn_B: bool = False
    sample: bool = True
    tol: float | None = None
    sampling: str = "policy"


class AgentParams(NamedTuple):
    """Everything an agent's behaviour depends on that is an array (fit, batch or differentiate it).

    Attributes
    ----------
    arrays : JaxModel
        The model (A, B, C, D, C_states, pA, pB, masks).
    gamma : jax.Array
        Policy precision.
    weights : EFEWeights
        Weight of each EFE term.
    lr_A, lr_B : jax.Array
        Learning rates of ``A`` and ``B``.
    log_E : jax.Array
        ``(P,)`` log habits over the enumerated policies (uniform by default).
    alpha : jax.Array
        Action precision.
    """

    arrays: JaxModel
    gamma: jax.Array
    weights: je.EFEWeights
    lr_A: jax.Array
    lr_B: jax.Array
    log_E: jax.Array
    alpha: jax.Array


class AgentState(NamedTuple):
    """The agent between steps (a pytree).

    Attributes
    ----------
    params : AgentParams
        Its parameters (the model arrays change when it learns).
    prior : tuple of jax.Array
        ``(capacity[f],)`` belief per factor before this step's observation.
    qs : tuple of jax.Array
        Posterior of the last step (the prior before the first step).
    action : jax.Array
        ``(F,)`` int controls chosen at the last step.
    key : jax.Array
        Random key (action sampling).
    t : jax.Array
        Steps taken.
    prep : Prepared
        Column entropies and novelty weights of ``params.arrays`` (recomputed only after learning).
    """

    params: AgentParams
    prior: tuple
    qs: tuple
    action: jax.Array
    key: jax.Array
    t: jax.Array
    prep: je.Prepared


class StepInfo(NamedTuple):
    """What one step did (arrays; batched along with the state under vmap).

    Attributes
    ----------
    qs : tuple of jax.Array
        ``(capacity[f],)`` posterior per factor.
    action : jax.Array
        ``(F,)`` int controls applied (the given ones when ``action=`` was passed).
    q_pi : jax.Array
        ``(P,)`` policy posterior.
    G : jax.Array
        ``(P,)`` expected free energy per policy.
    action_probs : jax.Array
        Shaped ``num_controls``: the probability of each control combination (sums to 1).
    free_energy : jax.Array
        Variational free energy (nats) of this step's inference.
    """

    qs: tuple
    action: jax.Array
    q_pi: jax.Array
    G: jax.Array
    action_probs: jax.Array
    free_energy: jax.Array


class Agent(NamedTuple):
    """A JAX-backend agent: its static config, its parameters and pure ``init``/``step``.

    Attributes
    ----------
    config : JaxConfig
    params : AgentParams
    """

    config: JaxConfig
    params: AgentParams

    def init(self, key, params: AgentParams | None = None) -> AgentState:
        """A fresh state (prior ``D``) with ``key`` (a ``jax.random.key``) and these parameters.

        Parameters
        ----------
        key : jax.Array
            Random key of the agent's action sampling.
        params : AgentParams, optional
            Parameters to start from; default the agent's.

        Returns
        -------
        AgentState
        """
        return init(self.config, self.params if params is None else params, key)

    def step(self, state: AgentState, obs, action=None) -> tuple[AgentState, StepInfo]:
        """One step (pure): see :func:`step`.

        Parameters
        ----------
        state : AgentState
        obs : tuple of jax.Array
            One ``(obs_capacity[m],)`` vector per modality (:func:`observation`).
        action : jax.Array, optional
            ``(F,)`` int controls to apply in place of the agent's own choice.

        Returns
        -------
        state : AgentState
        info : StepInfo
        """
        return step(self.config, state, obs, action)


def build(
    model: Model,
    *,
    scheme: str = "fpi",
    policy_len: int = 1,
    gamma: float = 16.0,
    objective: efe.Objective | str | None = None,
    learn_A: bool = False,
    learn_B: bool = False,
    lr_A: float = 1.0,
    lr_B: float = 1.0,
    sample: bool = True,
    num_iter: int = 16,
    tau: float | None = None,
    tol: float | None = None,
    goal_states=None,
    dtype=None,
    E=None,
    alpha: float = 1.0,
    sampling: str = "policy",
) -> Agent:
    """A JAX-backend agent for a dense compiled model, with the settings of :func:`cogmap.loop.init`.

    Parameters
    ----------
    model : Model
        Compiled model with dense transitions.
    scheme : str, optional
        ``"exact"``, ``"filter"``, ``"fpi"`` (default), ``"vmp"`` (coordinate ascent on the
        mean-field free energy), ``"vmp_pymdp"`` or ``"mmp"`` (pymdp 1.0's simultaneous updates).
    policy_len : int, optional
        Steps per enumerated policy, default 1.
    gamma : float, optional
        Policy precision, default 16.
    objective : Objective or str, optional
        An Objective of the terms :mod:`cogmap.planning.jax_efe` has, or a mode name of
        ``planning.decide.MODES``; default pymdp's (utility + state information gain).
    learn_A, learn_B : bool, optional
        Learn the likelihood / the transitions (need ``pA`` / ``pB``).
    lr_A, lr_B : float, optional
        Learning rates, default 1.
    sample : bool, optional
        Sample actions (default) or take the most probable policy.
    num_iter : int, optional
        Sweeps of fpi, vmp, vmp_pymdp and mmp, default 16.
    tau : float, optional
        Step size of vmp_pymdp and mmp, default 1 (the other schemes refuse it).
    tol : float, optional
        fpi and vmp stop after the first sweep in which no belief moves by more than ``tol`` (the
        numpy schemes' option); default None (always ``num_iter`` sweeps, as pymdp).
    goal_states : array_like, optional
        Goal states of the inductive term (default: from ``C_states``, as the numpy planner).
    dtype : numpy dtype, optional
        Float type of the arrays (default JAX's).
    E, alpha, sampling : optional
        Habits over the enumerated policies, action precision and sampling mode, as for
        :func:`cogmap.loop.init` (:mod:`cogmap.planning.action_selection`); ``E`` and ``alpha``
        are parameters (``params.log_E``, ``params.alpha``) that can be fitted or batched.

    Returns
    -------
    Agent

    Raises
    ------
    TypeError
        If ``model`` is not a compiled Model.
    ValueError
        For an unknown scheme, an objective term the JAX backend does not have, or invalid
        ``policy_len`` / ``gamma`` / ``num_iter`` / ``tol`` / ``E`` / ``alpha`` / ``sampling``, or
        ``tol`` / ``tau`` given to a scheme that does not take it.
    SpecError
        For sparse transitions, transitions that depend on several factors (``B_dependencies``, not
        yet on the JAX backend), or learning without the counts it needs.
    """
    if not isinstance(model, Model):
        raise TypeError(f"build needs a compiled Model (cogmap.genmodel.compile), got {type(model).__name__}")
    model.refuse_B_deps("the JAX backend (jax_agent.build)")
    if scheme not in js.SCHEMES:
        raise ValueError(f"unknown scheme {scheme!r} on the JAX backend (known: {', '.join(js.SCHEMES)})")
    if scheme == "filter" and len(model.factors) != 1:
        raise ValueError(f"filter is a single-factor scheme; the model has {len(model.factors)} factors")
    if not (isinstance(num_iter, int | np.integer) and num_iter >= 1):
        raise ValueError(f"num_iter must be an integer >= 1, got {num_iter!r}")
    if tol is not None and not (isinstance(tol, int | float | np.floating) and np.isfinite(tol) and tol > 0):
        raise ValueError(f"tol must be a positive number or None, got {tol!r}")
    for option, value in (("tol", tol), ("tau", tau)):
        if value is not None and option not in js.OPTIONS[scheme]:
            takers = " and ".join(name for name, opts in js.OPTIONS.items() if option in opts)
            why = " (its coordinate updates are exact steps; pymdp 1.0's damped ones are 'vmp_pymdp')" \
                if (option, scheme) == ("tau", "vmp") else ""
            raise ValueError(f"{option} is an option of {takers}, not of {scheme!r}{why}")
    objective = check_plan_settings(policy_len, gamma, objective)
    alpha = check_selection(alpha, sampling)
    policies = enumerate_policies(model.num_controls, int(policy_len))
    log_E = np.full(len(policies), -np.log(len(policies))) if E is None else check_habits(E, len(policies))
    weights = je.weights_of(objective or efe.pymdp_like())
    if learn_A and any(model.A[m].counts is None for m in range(len(model.modalities))):
        raise SpecError("learn_A needs Dirichlet counts (pA) for every modality")
    if learn_B and any(model.B[f].counts is None for f in range(len(model.factors))):
        raise SpecError("learn_B needs dense transitions with Dirichlet counts (pB) for every factor")
    f_goal = model.pose.factor if model.pose is not None else 0
    layout, arrays = to_jax(model, goal_dist=je.goal_distances_of(model, goal_states), goal_factor=f_goal,
                            dtype=dtype)
    config = JaxConfig(layout, scheme, int(num_iter), 1.0 if tau is None else float(tau), _nested(policies),
                       bool(learn_A), bool(learn_B), bool(sample), None if tol is None else float(tol), sampling)
    dt = arrays.D[0].dtype
    w = je.EFEWeights(*(jnp.asarray(x, dtype=dt) for x in weights))
    params = AgentParams(arrays, jnp.asarray(gamma, dtype=dt), w, jnp.asarray(lr_A, dtype=dt),
                         jnp.asarray(lr_B, dtype=dt), jnp.asarray(log_E, dtype=dt), jnp.asarray(alpha, dtype=dt))
    return Agent(config, params)


def _nested(a: np.ndarray):
    return tuple(_nested(x) for x in a) if a.ndim else int(a)


def init(config: JaxConfig, params: AgentParams, key) -> AgentState:
    """A fresh state: the prior is ``D``, no action taken yet (pure)."""
    prior = tuple(params.arrays.D)
    action = jnp.zeros(config.layout.num_factors, dtype=jnp.int32)
    return AgentState(params, prior, prior, action, key, jnp.asarray(0, dtype=jnp.int32), je.prepare(params.arrays))


def observation(layout: Layout, observation) -> tuple:
    """Observation vectors (one per modality) from an observation as :func:`cogmap.loop.step` takes it.

    Parameters
    ----------
    layout : Layout
    observation : sequence
        One entry per modality: an outcome index, a distribution, or None (missing).

    Returns
    -------
    tuple of jax.Array
    """
    return tuple(jnp.asarray(v) for v in js.one_hot_observation(layout, observation))


def _normalise(x):
    s = jnp.sum(x, axis=0, keepdims=True)
    return jnp.where(s > 0, x / jnp.where(s > 0, s, 1.0), 0.0)


def learn_A(layout: Layout, arrays: JaxModel, obs, qs, lr) -> JaxModel:
    """Dirichlet update ``pA += lr * o (x) q(deps)`` of every reporting modality, ``A`` renormalised
    where the numpy update renormalises it (the touched columns for one dependency, every live
    column for several)."""
    A, pA = list(arrays.A), list(arrays.pA)
    for m, deps in enumerate(layout.A_deps):
        outer = obs[m]
        for f in deps:
            outer = jnp.multiply.outer(outer, qs[f])
        new = pA[m] + lr * outer
        new = jnp.where(outer > 0, jnp.maximum(new, 1e-3), new)
        if len(deps) == 1:
            cols = (qs[deps[0]] > 0)[None, :]
        else:
            cols = jnp.sum(pA[m], axis=0, keepdims=True) > 0
        present = jnp.sum(obs[m]) > 0
        A[m] = jnp.where(present & cols, _normalise(new), A[m])
        pA[m] = jnp.where(present, new, pA[m])
    return arrays._replace(A=tuple(A), pA=tuple(pA))


def learn_B(arrays: JaxModel, qs, qs_prev, action, lr) -> JaxModel:
    """Dirichlet update ``pB[:, :, u] += lr * q_t (x) q_t-1`` of every factor, the columns the
    previous belief reaches renormalised (numpy ``DenseTransitions.learn_soft``)."""
    B, pB = list(arrays.B), list(arrays.pB)
    for f in range(len(B)):
        u = action[f]
        outer = lr * jnp.outer(qs[f], qs_prev[f])
        block = pB[f][:, :, u] + outer
        block = jnp.where(outer > 0, jnp.maximum(block, 1e-3), block)
        pB[f] = pB[f].at[:, :, u].set(block)
        cols = (qs_prev[f] > 0)[None, :]
        B[f] = B[f].at[:, :, u].set(jnp.where(cols, _normalise(block), B[f][:, :, u]))
    return arrays._replace(B=tuple(B), pB=tuple(pB))


def step(config: JaxConfig, state: AgentState, obs, action=None) -> tuple[AgentState, StepInfo]:
    """Infer, learn, plan and act for one observation (pure; jit it with ``config`` static).

    Parameters
    ----------
    config : JaxConfig
    state : AgentState
    obs : tuple of jax.Array
        One ``(obs_capacity[m],)`` vector per modality: one-hot, a distribution, or zeros (missing).
    action : jax.Array, optional
        ``(F,)`` int controls to apply instead of the agent's choice (a subject's).

    Returns
    -------
    state : AgentState
    info : StepInfo
    """
    layout, p = config.layout, state.params
    arrays = p.arrays
    ev = js.evidence(layout, arrays, obs)
    opts = {"num_iter": config.num_iter, "tau": config.tau, "tol": config.tol}
    kw = {k: opts[k] for k in js.OPTIONS[config.scheme]}
    qs, F = js.SCHEMES[config.scheme](layout, arrays, state.prior, ev, **kw)
    if config.learn_A:
        arrays = learn_A(layout, arrays, obs, qs, p.lr_A)
    if config.learn_B:
        learnt = learn_B(arrays, qs, state.qs, state.action, p.lr_B)
        arrays = jax.tree_util.tree_map(lambda new, old: jnp.where(state.t > 0, new, old), learnt, arrays)
    policies = np.asarray(config.policies, dtype=np.int32)
    prep = je.prepare(arrays) if config.learn_A or config.learn_B else state.prep
    G = je.policy_efe(layout, arrays, prep, p.weights, qs, jnp.asarray(policies))
    q_pi = jax.nn.softmax(p.log_E - p.gamma * G)  # Eq. (4), with habits
    probs = je.action_distribution(q_pi, policies, layout.num_controls, p.alpha, config.sampling)
    key, sub = jax.random.split(state.key)
    if action is None:
        action = je.choose_action(sub, q_pi, policies, layout.num_controls, p.alpha, config.sampling,
                                  config.sample)
    action = jnp.asarray(action, dtype=jnp.int32)
    prior = js.predict(arrays, qs, action)
    params = p._replace(arrays=arrays)
    nxt = AgentState(params, prior, qs, action, key, state.t + 1, prep)
    return nxt, StepInfo(qs, action, q_pi, G, probs, F)


class Trajectory(NamedTuple):
    """One episode of :func:`rollout` (arrays with a leading time axis).

    Attributes
    ----------
    obs : tuple of jax.Array
        Per modality ``(T, obs_capacity[m])`` observation vectors the agent received.
    actions : jax.Array
        ``(T, F)`` int controls it applied.
    info : StepInfo
        Its step reports, stacked over time.
    state : AgentState
        Its state after the last step.
    """

    obs: tuple
    actions: jax.Array
    info: StepInfo
    state: AgentState


def rollout(agent: Agent, world, key, steps: int, params: AgentParams | None = None) -> Trajectory:
    """A whole episode of ``agent`` against a pure JAX ``world`` as one ``lax.scan`` (jit and vmap it).

    Parameters
    ----------
    agent : Agent
    world : cogmap.envs.jax_worlds.World
        The generative process (:mod:`cogmap.envs.jax_worlds`).
    key : jax.Array
        Random key of the episode (world and action sampling).
    steps : int
        Observations (one action after each).
    params : AgentParams, optional
        Parameters to act with (default the agent's).

    Returns
    -------
    Trajectory
    """
    from cogmap.envs import jax_worlds

    k_agent, k_world, k_steps = jax.random.split(key, 3)
    state = agent.init(k_agent, params)
    world_state, obs = jax_worlds.reset(world, k_world)

    def body(carry, k):
        state, world_state, obs = carry
        state, info = agent.step(state, obs)
        world_state, nxt = jax_worlds.step(world, world_state, info.action, k)
        return (state, world_state, nxt), (obs, info)

    (state, _, _), (seen, infos) = jax.lax.scan(body, (state, world_state, obs), jax.random.split(k_steps, steps))
    return Trajectory(seen, infos.action, infos, state)


#: ``in_axes``/``out_axes`` of a population sharing one model: parameters and their prepared
#: quantities unbatched, everything else batched (an agent that learns needs its own copy: batch all)
SHARED = AgentState(None, 0, 0, 0, 0, 0, None)


def population(agent: Agent, keys) -> AgentState:
    """States of ``len(keys)`` agents that share ``agent.params`` (one model; no learning).

    Step them with ``jax.vmap(agent.step, in_axes=(SHARED, 0), out_axes=(SHARED, 0))``; the model
    arrays are then stored once, not once per agent.

    Parameters
    ----------
    agent : Agent
        A non-learning agent.
    keys : jax.Array
        ``(N,)`` random keys, one per agent.

    Returns
    -------
    AgentState
        Batched except ``params`` and ``prep``.

    Raises
    ------
    ValueError
        If the agent learns (learning agents each change their own copy).
    """
    if agent.config.learn_A or agent.config.learn_B:
        raise ValueError("agents that learn change their own parameters: batch them with jax.vmap(agent.init)")
    states = jax.vmap(agent.init)(keys)
    return states._replace(params=agent.params, prep=je.prepare(agent.params.arrays))


#: :func:`step` jitted with the config static (one compilation per config and array shapes)
jitted_step = jax.jit(step, static_argnums=0)


__all__ = ["SHARED", "Agent", "AgentParams", "AgentState", "JaxConfig", "StepInfo", "build", "init", "jitted_step",
           "learn_A", "learn_B", "observation", "population", "rollout", "step", "Trajectory"]

"""An active-inference agent for any compiled model: ``init`` and ``step`` over a small state.

    state = init(model, scheme="fpi", planner="enumerate", policy_len=2, gamma=16.0)
    state, info = step(state, observation)      # infer -> learn (optional) -> plan -> act
    info.action, info.q_pi, info.qs

One ``step`` takes the observation of this time step (one entry per modality, an index or a
distribution; a dict by name works too), infers the state posterior with the registered
inference scheme, optionally learns ``A`` (Eq. 8: counts += lr * o (x) q) and ``B`` (counts +=
lr * q_t (x) q_t-1 for the control taken; dense transitions), evaluates policies by expected
free energy with the planner registered under ``planner`` (built in: "enumerate", every policy
of ``policy_len`` steps, or "mcts"; add one with :func:`cogmap.planning.register_planner`) and
picks the next control. The prior of the next step is the posterior pushed through ``B`` under that control.

The state is an immutable tuple; the model it holds is learnt in place when learning is on (as
pymdp's ``Agent`` does). Policy precision ``gamma`` defaults to 16 (cogmap's planners); pymdp's
``Agent`` defaults to 1: pass the same value to compare them.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import NamedTuple

import numpy as np

from cogmap import inference
from cogmap.genmodel import Model, SpecError
from cogmap.inference.exact import MAX_JOINT
from cogmap.inference.learning import learn_observation
from cogmap.inference.registry import check_options
from cogmap.planning import efe
from cogmap.planning.action_selection import check_habits, check_selection, control_probabilities
from cogmap.planning.decide import check_plan_settings
from cogmap.planning.mcts import MCTSConfig
from cogmap.planning.planners import PlanSettings, available_planners, get_planner
from cogmap.planning.policies import enumerate_policies


class LoopConfig(NamedTuple):
    """Settings of an agent built by :func:`init` (see its parameters).

    Attributes
    ----------
    scheme : str
        Registered inference scheme, default ``"fpi"``.
    planner : str
        ``"enumerate"`` (default) or ``"mcts"``.
    policy_len : int
        Steps per enumerated policy, default 1.
    gamma : float
        Policy precision, default 16.
    objective : Objective or None
        Per-step EFE (``init`` fills in ``efe.pymdp_like()`` when none is given).
    mcts : MCTSConfig or None
        MCTS settings; default ``MCTSConfig(gamma=gamma)``.
    learn_A, learn_B : bool
        Whether to learn the likelihood / the transitions, default False.
    lr_A, lr_B : float
        Their learning rates, default 1.
    sample : bool
        Sample the action from the policy posterior (False: its mode); default True.
    scheme_options : dict or None
        Keyword options of the inference scheme.
    log_E : numpy.ndarray or None
        ``(P,)`` float log habits over the enumerated policies (None: uniform).
    alpha : float
        Action precision, default 1.
    sampling : str
        ``"policy"`` (default) or ``"marginal"`` (:mod:`cogmap.planning.action_selection`).
    lr_D, lr_E : float
        Learning rates of ``pD`` and ``pE`` (:func:`reset`).
    """
    scheme: str = "fpi"
    planner: str = "enumerate"
    policy_len: int = 1
    gamma: float = 16.0
    objective: efe.Objective | None = None
    mcts: MCTSConfig | None = None
    learn_A: bool = False
    learn_B: bool = False
    lr_A: float = 1.0
    lr_B: float = 1.0
    sample: bool = True  # sample the action from the policy posterior (False: its mode)
    scheme_options: dict | None = None
    log_E: np.ndarray | None = None  # log habits over the enumerated policies (None: uniform)
    alpha: float = 1.0  # action precision
    sampling: str = "policy"  # "policy" or "marginal"
    lr_D: float = 1.0  # learning rate of pD (at reset)
    lr_E: float = 1.0  # learning rate of pE (at reset)


class LoopState(NamedTuple):
    """The agent's immutable state between steps.

    Attributes
    ----------
    model : Model
        The compiled model (learnt in place when learning is on).
    config : LoopConfig
        The agent's settings.
    prior : list of numpy.ndarray
        ``(num_states[f],)`` float belief over each factor before this step's observation.
    qs : list of numpy.ndarray or None
        Posterior of the last step (None before the first).
    action : tuple of int or None
        Control per factor chosen at the last step.
    rng : numpy.random.Generator
        Random generator (action sampling, MCTS).
    t : int
        Number of steps taken in this trial (:func:`reset` starts a new one).
    pD : tuple of numpy.ndarray or None
        Dirichlet counts of the initial state per factor (``init(pD=...)``), learnt by :func:`reset`.
    pE : numpy.ndarray or None
        Dirichlet counts of the habits (``init(pE=...)``), learnt by :func:`reset`.
    trial : tuple or None
        With ``pD``: the trial so far, ``(prior, observations, actions)`` (what ``pD`` learns from).
    q_pi : numpy.ndarray or None
        Policy posterior of the last step (what ``pE`` learns from).
    """
    model: Model
    config: LoopConfig
    prior: list  # belief over each factor before this step's observation
    qs: list | None  # posterior of the last step
    action: tuple | None  # control chosen at the last step (one per factor)
    rng: np.random.Generator
    t: int
    pD: tuple | None = None  # Dirichlet counts of the initial state (learnt at reset)
    pE: np.ndarray | None = None  # Dirichlet counts of the habits (learnt at reset)
    trial: tuple | None = None  # with pD: (prior, observations, actions) of the trial so far
    q_pi: np.ndarray | None = None  # policy posterior of the last step


class StepInfo(NamedTuple):
    """What happened in one :func:`step`.

    Attributes
    ----------
    qs : list of numpy.ndarray
        ``(num_states[f],)`` float posterior per factor.
    action : tuple of int
        Control per factor to apply now.
    q_pi : numpy.ndarray or None
        ``(P,)`` float policy posterior (enumeration); None with MCTS.
    G : numpy.ndarray
        Expected free energy per policy ``(P,)`` (enumeration) or backed-up value per root action
        (MCTS).
    policies : numpy.ndarray or None
        ``(P, T, F)`` int policies of ``q_pi`` and ``G`` (enumeration).
    free_energy : float
        Variational free energy (nats) of this step's inference.
    action_probs : numpy.ndarray or None
        Shaped ``num_controls``: the probability of each control combination, what a sampling
        agent draws from (with ``alpha`` 1 and ``sampling="policy"``, the marginal of ``q_pi``
        over the first step; :mod:`cogmap.planning.action_selection`); None with MCTS.
    """
    qs: list  # posterior per factor
    action: tuple  # control per factor to apply now
    q_pi: np.ndarray | None  # policy posterior (enumeration), None with MCTS
    G: np.ndarray  # expected free energy per policy (enumeration) or per root action (MCTS)
    policies: np.ndarray | None  # (P, T, F) policies of q_pi and G (enumeration)
    free_energy: float  # variational free energy of this step's inference
    action_probs: np.ndarray | None = None  # probability of each first-step control combination


def init(
    model: Model,
    *,
    scheme: str = "fpi",
    planner: str = "enumerate",
    policy_len: int = 1,
    gamma: float = 16.0,
    objective: efe.Objective | str | None = None,
    mcts: MCTSConfig | None = None,
    learn_A: bool = False,
    learn_B: bool = False,
    lr_A: float = 1.0,
    lr_B: float = 1.0,
    sample: bool = True,
    seed: int = 0,
    backend: str = "numpy",
    E=None,
    alpha: float = 1.0,
    sampling: str = "policy",
    pD=None,
    pE=None,
    lr_D: float = 1.0,
    lr_E: float = 1.0,
    **scheme_options,
):
    """A fresh agent on ``model``; the prior is ``D``.

    Parameters
    ----------
    model : Model
        Compiled model.
    scheme : str, optional
        Name in the inference registry (``cogmap.inference.register``), default ``"fpi"``.
    planner : str, optional
        Name in the planner registry (``cogmap.planning.register_planner``): ``"enumerate"``
        (every policy of ``policy_len`` steps, default), ``"mcts"``, or one of your own.
    policy_len : int, optional
        Policy length for enumeration, an integer >= 1; default 1.
    gamma : float, optional
        Policy precision, positive; default 16 (pymdp's ``Agent`` defaults to 1).
    objective : Objective or str, optional
        An :class:`~cogmap.planning.efe.Objective` or a name of ``planning.decide.MODES``
        (``"pymdp"``: utility + state information gain, the default; ``"explore"``, ``"goal"``,
        ``"full"``, ``"sensed"``).
    mcts : MCTSConfig, optional
        MCTS settings.
    learn_A : bool, optional
        Learn ``A`` after each inference (Eq. 8 of the AIMAPP paper); needs ``pA`` for every modality.
    learn_B : bool, optional
        Learn ``B`` for the control taken; needs dense transitions with ``pB`` for every factor.
    lr_A, lr_B : float, optional
        Learning rates, default 1.
    sample : bool, optional
        Sample actions (default) instead of taking the mode (:mod:`cogmap.planning.action_selection`).
    seed : int, optional
        Seed of the agent's generator, default 0.
    backend : str, optional
        ``"numpy"`` (default: every scheme, planner and model, sparse growing maps included) or
        ``"jax"``: the jitted step of :mod:`cogmap.jax_agent` (dense models, the enumerate
        planner, the schemes and EFE terms it has), returned as a :class:`JaxLoop` that
        :func:`step` runs the same way.
    E : array_like, optional
        Habits: ``(P,)`` positive prior weights over the ``P`` enumerated policies, in the order of
        :func:`cogmap.planning.enumerate_policies` (normalised here); ``q(pi) = softmax(ln E -
        gamma G)``. Default uniform. Enumerate planner only.
    alpha : float, optional
        Action precision: controls are drawn from ``softmax(alpha ln q)``; default 1 (pymdp's
        ``Agent`` defaults to 1 too).
    sampling : str, optional
        ``"policy"`` (default: a policy, then its first step; pymdp's ``sampling_mode="full"``) or
        ``"marginal"`` (each factor's control from its marginal; pymdp's default).
    pD : sequence of array_like, optional
        Dirichlet counts of the initial state, one ``(num_states[f],)`` non-negative vector per
        factor: the prior of each trial is ``pD`` normalised (instead of ``D``) and :func:`reset`
        learns it from the trial's first posterior (SPM's ``d``).
    pE : array_like, optional
        Dirichlet counts of the habits over the enumerated policies (positive): ``E`` is ``pE``
        normalised and :func:`reset` learns it from the last policy posterior (SPM's ``e``). Not
        with ``E``.
    lr_D, lr_E : float, optional
        Their learning rates (SPM's ``eta``), default 1.
    **scheme_options
        Passed to the inference scheme (e.g. ``num_iter=16``).

    Returns
    -------
    LoopState or JaxLoop

    Raises
    ------
    TypeError
        If ``model`` is not a compiled :class:`Model`.
    KeyError
        For an unknown inference scheme.
    ValueError
        For an unknown planner or objective name, invalid ``policy_len`` / ``gamma`` / ``E`` /
        ``alpha`` / ``sampling``;
        :class:`~cogmap.inference.InferenceError` for a scheme option the scheme does not accept
        (:func:`cogmap.inference.registry.options`).
    SpecError
        If learning is asked for without the counts it needs.
    """
    if not isinstance(model, Model):
        raise TypeError(f"init needs a compiled Model (cogmap.genmodel.compile), got {type(model).__name__}")
    inference.get(scheme)  # unknown names fail here, listing the known ones
    check_options(scheme, scheme_options)  # and options the scheme does not take, naming them
    if not isinstance(planner, str) or planner not in available_planners():
        raise ValueError(f"unknown planner {planner!r} (known: {', '.join(available_planners())})")
    objective = check_plan_settings(policy_len, gamma, objective)
    if learn_A and not all(model.has_counts_A(m) for m in range(len(model.modalities))):
        raise SpecError("learn_A needs Dirichlet counts (pA) for every modality")
    if learn_B and any(model.B[f].counts is None or model.is_sparse(f) for f in range(len(model.factors))):
        raise SpecError("learn_B needs dense transitions with Dirichlet counts (pB) for every factor")
    alpha = check_selection(alpha, sampling)
    log_E = None
    if E is not None:
        if planner != "enumerate":
            raise ValueError(f"E (habits) weighs the enumerated policies: it needs planner 'enumerate', "
                             f"not {planner!r}")
        log_E = check_habits(E, len(enumerate_policies(model.num_controls, int(policy_len))))
    num_policies = len(enumerate_policies(model.num_controls, int(policy_len)))
    pD, pE = _check_prior_counts(model, pD, pE, E, lr_D, lr_E, planner, num_policies)
    if pE is not None:
        log_E = check_habits(pE, num_policies)
    if backend == "jax":
        if pD is not None or pE is not None:
            raise ValueError("learning D or E (pD, pE) is not available on the jax backend yet")
        return _jax_init(model, scheme, planner, policy_len, gamma, objective, mcts, learn_A, learn_B, lr_A,
                         lr_B, sample, seed, scheme_options, dict(E=E, alpha=alpha, sampling=sampling))
    if backend != "numpy":
        raise ValueError(f"unknown backend {backend!r} (known: numpy, jax)")
    cfg = LoopConfig(scheme, planner, int(policy_len), float(gamma), objective or efe.pymdp_like(), mcts,
                     learn_A, learn_B, lr_A, lr_B, sample, scheme_options or None, log_E, alpha, sampling,
                     float(lr_D), float(lr_E))
    return LoopState(model, cfg, _trial_prior(model, pD), None, None, np.random.default_rng(seed), 0, pD, pE)


def _trial_prior(model: Model, pD) -> list:
    if pD is None:
        return [model.live_D(f).copy() for f in range(len(model.factors))]
    return [d / d.sum() for d in pD]


def _check_prior_counts(model: Model, pD, pE, E, lr_D, lr_E, planner, num_policies):
    for name, lr in (("lr_D", lr_D), ("lr_E", lr_E)):
        if isinstance(lr, bool) or not isinstance(lr, int | float | np.integer | np.floating) \
                or not np.isfinite(lr) or lr < 0:
            raise ValueError(f"{name} must be a finite non-negative number, got {lr!r}")
    if pD is not None:
        F = len(model.factors)
        if isinstance(pD, np.ndarray) and pD.ndim == 1 and F == 1:
            pD = [pD]
        if isinstance(pD, str | bytes) or not isinstance(pD, Sequence | np.ndarray) or len(pD) != F:
            raise ValueError(f"pD must hold one count vector per factor ({F})")
        out = []
        for f, d in enumerate(pD):
            arr = np.asarray(d, dtype=float)
            n = model.num_states[f]
            if arr.shape != (n,) or not np.all(np.isfinite(arr)) or np.any(arr < 0) or arr.sum() <= 0:
                raise ValueError(f"pD for factor '{model.factors[f].name}' must be {n} finite non-negative "
                                 f"counts with a positive sum, got shape {arr.shape}")
            out.append(arr.copy())
        pD = tuple(out)
    if pE is not None:
        if E is not None:
            raise ValueError("give E (fixed habits) or pE (learnt habits), not both")
        if planner != "enumerate":
            raise ValueError(f"pE (habits) weighs the enumerated policies: it needs planner 'enumerate', "
                             f"not {planner!r}")
        check_habits(pE, num_policies)
        pE = np.asarray(pE, dtype=float).copy()
    return pD, pE


def reset(state):
    """Start a new trial: learn ``pD`` and ``pE`` from the trial that ended, then begin from the prior.

    With ``pD`` (SPM's ``spm_MDP_VB_X``): ``pD_f[i] += lr_D * q_1^f[i]`` wherever ``pD_f[i] > 0``,
    ``q_1`` the belief about the trial's first state given the whole trial, as SPM's ``X(:, 1)``
    at the end of a trial: the exact smoothed first marginal over the trial's observations and
    actions when the joint state space is within the ``exact`` scheme's ``MAX_JOINT``, else that
    of ``mmp`` (marginal message passing, SPM's own scheme). With ``pE``:
    ``pE += lr_E * q(pi)`` of the trial's last step. The next trial's prior is ``pD`` normalised
    (else ``D``), its habits ``pE`` normalised; the model (and what it learnt of ``A`` and ``B``)
    and the random generator carry over.

    Parameters
    ----------
    state : LoopState
        The agent at the end of a trial.

    Returns
    -------
    LoopState
        The agent at the start of the next trial (``t = 0``).

    Raises
    ------
    TypeError
        For a JAX-backend agent (start a new one with ``agent.init``).
    """
    if not isinstance(state, LoopState):
        raise TypeError(f"reset takes a numpy-backend LoopState, got {type(state).__name__}")
    cfg = state.config
    pD, pE = state.pD, state.pE
    if pD is not None and state.trial is not None:
        prior, observations, actions = state.trial
        small = int(np.prod(state.model.num_states)) <= MAX_JOINT
        _, info = inference.get("exact" if small else "mmp")(state.model, prior, observations, actions)
        first = info.history[0]
        pD = tuple(d + np.where(d > 0, cfg.lr_D * np.asarray(q), 0.0) for d, q in zip(pD, first, strict=True))
    if pE is not None and state.q_pi is not None:
        pE = pE + cfg.lr_E * state.q_pi
        cfg = cfg._replace(log_E=np.log(pE / pE.sum()))
    return LoopState(state.model, cfg, _trial_prior(state.model, pD), None, None, state.rng, 0, pD, pE)


class JaxLoop(NamedTuple):
    """An agent of :func:`init` with ``backend="jax"``: :func:`step` runs its jitted step.

    Attributes
    ----------
    model : Model
        The model it was built from (not changed: learning happens in ``state.params``).
    agent : cogmap.jax_agent.Agent
        The static config and the parameters.
    state : cogmap.jax_agent.AgentState
        The pure state.
    """
    model: Model
    agent: object
    state: object


def _jax_init(model, scheme, planner, policy_len, gamma, objective, mcts, learn_A, learn_B, lr_A, lr_B, sample,
              seed, scheme_options, selection) -> JaxLoop:
    import jax

    from cogmap import jax_agent

    if planner != "enumerate" or mcts is not None:
        raise ValueError(f"the jax backend plans by enumeration only (planner 'enumerate'), got {planner!r}")
    agent = jax_agent.build(model, scheme=scheme, policy_len=int(policy_len), gamma=gamma, objective=objective,
                            learn_A=learn_A, learn_B=learn_B, lr_A=lr_A, lr_B=lr_B, sample=sample,
                            **selection, **(scheme_options or {}))
    return JaxLoop(model, agent, agent.init(jax.random.key(seed)))


def _jax_step(loop_state: JaxLoop, observation, action):
    from cogmap import jax_agent

    model, agent = loop_state.model, loop_state.agent
    obs = jax_agent.observation(agent.config.layout, _observation(model, observation))
    given = None if action is None else np.asarray(_given_action(model, action), dtype=np.int32)
    state, info = jax_agent.jitted_step(agent.config, loop_state.state, obs, given)
    n = model.num_states
    qs = [np.asarray(q)[: n[f]] for f, q in enumerate(info.qs)]
    out = StepInfo(qs, tuple(int(a) for a in np.asarray(info.action)), np.asarray(info.q_pi), np.asarray(info.G),
                   np.asarray(agent.config.policies), float(info.free_energy), np.asarray(info.action_probs))
    return loop_state._replace(state=state), out


def _observation(model: Model, observation) -> list:
    if isinstance(observation, Mapping):
        out = [None] * len(model.modalities)
        for name, value in observation.items():
            out[model.modality_index(name)] = value
        return out
    if np.ndim(observation) == 0 and len(model.modalities) == 1:
        return [observation]
    if not isinstance(observation, Sequence | np.ndarray) or len(observation) != len(model.modalities):
        raise ValueError(f"an observation has one entry per modality ({len(model.modalities)}), got {observation!r}")
    return list(observation)


#: probability of each first-step control combination (the old name of
#: :func:`cogmap.planning.action_selection.control_probabilities`)
action_probabilities = control_probabilities

def _given_action(model: Model, action) -> tuple:
    acts = (action,) if np.ndim(action) == 0 else tuple(action)
    ok = len(acts) == len(model.factors) and all(
        isinstance(a, int | np.integer) and not isinstance(a, bool | np.bool_) and 0 <= a < u
        for a, u in zip(acts, model.num_controls, strict=False))
    if not ok:
        raise ValueError(f"action must be one integer control per factor, within {list(model.num_controls)}; "
                         f"got {action!r}")
    return tuple(int(a) for a in acts)


def step(state, observation, action=None):
    """Infer, learn, plan and act for one observation.

    Parameters
    ----------
    state : LoopState or JaxLoop
        The agent's state (a :class:`JaxLoop` from ``init(..., backend="jax")``).
    observation : sequence or dict or int
        One entry per modality (an outcome index, a distribution over outcomes or None), a dict by
        modality name, or a bare index for a single modality.
    action : tuple of int or int, optional
        Controls (one per factor) to apply in place of the agent's own choice, for example a
        subject's recorded choice: the step still evaluates its policies and reports
        ``action_probs``, then learns and predicts with this action.

    Returns
    -------
    state : LoopState
        The next state (its prior is the posterior pushed through ``B`` under the chosen control).
    info : StepInfo

    Raises
    ------
    ValueError
        If the observation does not have one entry per modality, or ``action`` is not one
        control per factor in range.
    """
    if isinstance(state, JaxLoop):
        return _jax_step(state, observation, action)
    model, cfg = state.model, state.config
    obs = _observation(model, observation)
    given = None if action is None else _given_action(model, action)
    qs, info = inference.get(cfg.scheme)(model, state.prior, [obs], **(cfg.scheme_options or {}))
    qs = [np.asarray(q, dtype=float) for q in qs]
    if cfg.learn_A:
        for m, o in enumerate(obs):
            if o is not None:
                learn_observation(model, m, o, qs, lr=cfg.lr_A)
    if cfg.learn_B and state.qs is not None:
        for f, u in enumerate(state.action):
            model.B[f].learn_soft(qs[f], state.qs[f], int(u), cfg.lr_B, model.num_states[f])
    settings = PlanSettings(cfg.policy_len, cfg.gamma, state.rng, cfg.sample, cfg.mcts, cfg.log_E, cfg.alpha,
                            cfg.sampling)
    plan = get_planner(cfg.planner)(model, qs, cfg.objective, settings)
    action = tuple(int(a) for a in plan.action)
    if len(action) != len(model.factors):
        raise ValueError(f"planner '{cfg.planner}' returned {len(action)} control(s), the model has "
                         f"{len(model.factors)} factor(s)")
    action = given or action
    q_pi, G, policies = plan.q_pi, np.asarray(plan.G), plan.policies
    probs = None if q_pi is None or policies is None else control_probabilities(q_pi, policies, model.num_controls,
                                                                                   cfg.alpha, cfg.sampling)
    prior = inference.base.predict_factorised(model, qs, action)
    trial = state.trial
    if state.pD is not None:  # the trial so far, for learning pD at reset
        trial = ((list(state.prior), [obs], []) if state.t == 0 else
                 (trial[0], trial[1] + [obs], trial[2] + [state.action]))
    nxt = state._replace(prior=prior, qs=qs, action=action, t=state.t + 1, trial=trial, q_pi=q_pi)
    return nxt, StepInfo(qs, action, q_pi, G, policies, float(info.free_energy), probs)

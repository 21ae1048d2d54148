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
from cogmap.inference.learning import learn_observation
from cogmap.inference.registry import check_options
from cogmap.planning import efe
from cogmap.planning.decide import MODES, make_objective
from cogmap.planning.mcts import MCTSConfig
from cogmap.planning.planners import PlanSettings, available_planners, get_planner


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
        Number of steps taken.
    """
    model: Model
    config: LoopConfig
    prior: list  # belief over each factor before this step's observation
    qs: list | None  # posterior of the last step
    action: tuple | None  # control chosen at the last step (one per factor)
    rng: np.random.Generator
    t: int


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
    """
    qs: list  # posterior per factor
    action: tuple  # control per factor to apply now
    q_pi: np.ndarray | None  # policy posterior (enumeration), None with MCTS
    G: np.ndarray  # expected free energy per policy (enumeration) or per root action (MCTS)
    policies: np.ndarray | None  # (P, T, F) policies of q_pi and G (enumeration)
    free_energy: float  # variational free energy of this step's inference


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
    **scheme_options,
) -> LoopState:
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
        Sample actions from the policy posterior (default) instead of taking its mode.
    seed : int, optional
        Seed of the agent's generator, default 0.
    **scheme_options
        Passed to the inference scheme (e.g. ``num_iter=16``).

    Returns
    -------
    LoopState

    Raises
    ------
    TypeError
        If ``model`` is not a compiled :class:`Model`.
    KeyError
        For an unknown inference scheme.
    ValueError
        For an unknown planner or objective name, or invalid ``policy_len`` / ``gamma``;
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
    if not (isinstance(policy_len, int | np.integer) and policy_len >= 1):
        raise ValueError(f"policy_len must be an integer >= 1, got {policy_len!r}")
    if not (np.isfinite(gamma) and gamma > 0):
        raise ValueError(f"gamma (policy precision) must be positive and finite, got {gamma!r}")
    if isinstance(objective, str):
        if objective not in MODES:
            raise ValueError(f"unknown objective '{objective}' (known: {', '.join(MODES)} or an Objective)")
        objective = make_objective(objective)
    if learn_A and not all(model.has_counts_A(m) for m in range(len(model.modalities))):
        raise SpecError("learn_A needs Dirichlet counts (pA) for every modality")
    if learn_B and any(model.B[f].counts is None or model.is_sparse(f) for f in range(len(model.factors))):
        raise SpecError("learn_B needs dense transitions with Dirichlet counts (pB) for every factor")
    cfg = LoopConfig(scheme, planner, int(policy_len), float(gamma), objective or efe.pymdp_like(), mcts,
                     learn_A, learn_B, lr_A, lr_B, sample, scheme_options or None)
    prior = [model.live_D(f).copy() for f in range(len(model.factors))]
    return LoopState(model, cfg, prior, None, None, np.random.default_rng(seed), 0)


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


def step(state: LoopState, observation) -> tuple[LoopState, StepInfo]:
    """Infer, learn, plan and act for one observation.

    Parameters
    ----------
    state : LoopState
        The agent's state.
    observation : sequence or dict or int
        One entry per modality (an outcome index, a distribution over outcomes or None), a dict by
        modality name, or a bare index for a single modality.

    Returns
    -------
    state : LoopState
        The next state (its prior is the posterior pushed through ``B`` under the chosen control).
    info : StepInfo

    Raises
    ------
    ValueError
        If the observation does not have one entry per modality.
    """
    model, cfg = state.model, state.config
    obs = _observation(model, observation)
    qs, info = inference.get(cfg.scheme)(model, state.prior, [obs], **(cfg.scheme_options or {}))
    qs = [np.asarray(q, dtype=float) for q in qs]
    if cfg.learn_A:
        for m, o in enumerate(obs):
            if o is not None:
                learn_observation(model, m, o, qs, lr=cfg.lr_A)
    if cfg.learn_B and state.qs is not None:
        for f, u in enumerate(state.action):
            model.B[f].learn_soft(qs[f], state.qs[f], int(u), cfg.lr_B, model.num_states[f])
    settings = PlanSettings(cfg.policy_len, cfg.gamma, state.rng, cfg.sample, cfg.mcts)
    plan = get_planner(cfg.planner)(model, qs, cfg.objective, settings)
    action = tuple(int(a) for a in plan.action)
    if len(action) != len(model.factors):
        raise ValueError(f"planner '{cfg.planner}' returned {len(action)} control(s), the model has "
                         f"{len(model.factors)} factor(s)")
    q_pi, G, policies = plan.q_pi, np.asarray(plan.G), plan.policies
    prior = [model.predict(f, qs[f], action[f]) for f in range(len(model.factors))]
    nxt = state._replace(prior=prior, qs=qs, action=action, t=state.t + 1)
    return nxt, StepInfo(qs, action, q_pi, G, policies, float(info.free_energy))

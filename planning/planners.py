"""Planners by name: how an agent loop turns a belief into the next control.

A planner is any callable

    plan = planner(model, qs, objective, settings)

* ``model``: the compiled :class:`cogmap.genmodel.Model` (or :class:`~.arrays.PlanningArrays`);
* ``qs``: the current belief, one array per factor (live length ``n_f``);
* ``objective``: an :class:`~.efe.Objective` (call it on a step context to get the per-step
  expected free energy ``G`` per candidate, lower is better);
* ``settings``: a :class:`PlanSettings` (policy length, precision, the loop's RNG, whether to
  sample, the MCTS configuration), read what you need and ignore the rest;

returning a :class:`Plan`: ``action`` (one integer control per factor), ``G`` (the EFE of what
was compared: per policy, per root action, ...) and optionally ``q_pi`` and ``policies``.
:mod:`cogmap.loop` calls it once per step, after inference and learning, and looks it up by the
name given to ``loop.init(planner=...)``. Four are built in: ``"enumerate"`` (every policy of
``policy_len`` steps, :func:`~.policies.infer_policies`), ``"mcts"`` (:func:`~.decide.decide`),
``"sophisticated"`` (expected free energy recursed over actions and outcomes, ``policy_len`` steps
deep, :func:`~.sophisticated.sophisticated_efe`) and
``"drone"`` (the drone's waypoint ranking, looking ``policy_len`` waypoints ahead, on a
:class:`~.drone_planner.DroneScene`, :func:`drone_planner`). Add yours with :func:`register_planner`
without touching this package; :func:`accepting_planners` lists those that take a given model.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np

from cogmap.genmodel import contracts
from cogmap.genmodel.drone_beliefs import entropy
from cogmap.genmodel.model import Model
from cogmap.genmodel.registry import Registry

from .arrays import PlanningArrays
from .drone_lookahead import LookaheadConfig, plan_sequence
from .drone_planner import DroneScene, plan_waypoints
from .mcts import MCTSConfig
from .plan import Plan


class PlanSettings(NamedTuple):
    """What the loop passes to every planner (a planner reads only what it needs).

    Attributes
    ----------
    policy_len : int
        Steps per policy (enumeration).
    gamma : float
        Policy precision: ``q(pi) = softmax(-gamma G)`` (Eq. 4 of the AIMAPP paper).
    rng : numpy.random.Generator or None
        The loop's generator; use it for any randomness so runs are reproducible.
    sample : bool
        Sample the action from ``q(pi)``; False takes its mode.
    mcts : MCTSConfig or None
        Depth and simulations for tree search (None: the defaults).
    log_E : numpy.ndarray or None
        ``(P,)`` log habits over the enumerated policies (None: uniform).
    alpha : float
        Action precision (:mod:`~.action_selection`), default 1.
    sampling : str
        ``"policy"`` (default) or ``"marginal"`` (:mod:`~.action_selection`).
    """

    policy_len: int = 1  # steps per policy (enumeration)
    gamma: float = 16.0  # policy precision, q(pi) = softmax(-gamma G) (Eq. 4)
    rng: np.random.Generator | None = None  # the loop's generator (the loop owns its state)
    sample: bool = True  # sample the action from q(pi); False: take its mode
    mcts: MCTSConfig | None = None  # depth / simulations for tree search (None: defaults)
    log_E: np.ndarray | None = None  # log habits over the enumerated policies (None: uniform)
    alpha: float = 1.0  # action precision
    sampling: str = "policy"  # "policy" or "marginal" (planning.action_selection)


Planner = Callable[..., Plan]

#: the registered planners; ``register_planner(name, fn, *, accepts=None, overwrite=False)``
#: (a decorator without ``fn``; ``accepts`` names the models it plans with), ``unregister_planner``,
#: ``get_planner``, ``available_planners`` and ``accepting_planners(model)`` are its methods. The
#: built-in ``enumerate``, ``mcts`` and ``drone`` can be neither replaced nor removed.
PLANNERS = Registry("planner", "register_planner", protocol=contracts.Planner, expected="a callable")
register_planner = PLANNERS.register
unregister_planner = PLANNERS.remove
get_planner = PLANNERS.get
available_planners = PLANNERS.available
accepting_planners = PLANNERS.accepting


# -- the two built-in planners -----------------------------------------------------------------
def enumerate_planner(model, qs, objective, settings: PlanSettings) -> Plan:
    """Every policy of ``settings.policy_len`` steps, ``q(pi) = softmax(ln E - gamma G)`` (Eq. 4).

    Parameters
    ----------
    model : Model or PlanningArrays
        The model to plan with.
    qs : list of numpy.ndarray
        Current belief, one ``(n_f,)`` array per factor.
    objective : Objective
        Per-step expected free energy.
    settings : PlanSettings
        Policy length, precision, RNG and whether to sample.

    Returns
    -------
    Plan
        First action of the chosen policy, ``G`` and ``q(pi)`` per policy, the policies.
    """
    from .policies import infer_policies

    rng = settings.rng if settings.sample else None
    action, q_pi, G, policies = infer_policies(model, qs, objective, length=settings.policy_len,
                                               gamma=settings.gamma, rng=rng, log_E=settings.log_E,
                                               alpha=settings.alpha, sampling=settings.sampling)
    return Plan(tuple(int(a) for a in action), G, q_pi, policies)


def mcts_planner(model, qs, objective, settings: PlanSettings) -> Plan:
    """MCTS over EFE (Appendix A.3 of the AIMAPP paper) through :func:`~.decide.decide`.

    Parameters
    ----------
    model, qs, objective
        As for :func:`enumerate_planner`.
    settings : PlanSettings
        ``settings.mcts`` (default: ``MCTSConfig(gamma=settings.gamma)``) and the RNG.

    Returns
    -------
    Plan
        The chosen control per factor (0 for factors the search does not move) and the
        backed-up EFE per root action; no ``q_pi``.
    """
    from .decide import decide

    mcfg = settings.mcts or MCTSConfig(gamma=settings.gamma)
    d = decide(model, qs, None, objective, config=mcfg, rng=settings.rng)
    a = np.atleast_1d(np.asarray(d.action, dtype=int))
    num_factors = len(qs)
    return Plan(tuple(int(x) for x in a) + (0,) * (num_factors - a.size), np.asarray(d.Q))


def sophisticated_planner(model, qs, objective, settings: PlanSettings) -> Plan:
    """Sophisticated inference, ``settings.policy_len`` steps deep
    (:func:`~.sophisticated.sophisticated_planner`, SPM's pruning).

    Parameters
    ----------
    model, qs, objective
        As for :func:`enumerate_planner`.
    settings : PlanSettings
        Horizon (``policy_len``), precision, RNG, whether to sample, action precision and sampling.

    Returns
    -------
    Plan
        The chosen control, ``G`` and ``q(u)`` per root joint control, those controls as ``(U, 1, F)``
        policies, the search's :class:`~.sophisticated.SophisticatedInfo`.
    """
    from .sophisticated import sophisticated_planner as plan

    return plan(model, qs, objective, settings)


def drone_planner(model: DroneScene, qs, objective, settings):
    """The ``"drone"`` planner: the paper's one-step waypoint
    ranking (:func:`~.drone_planner.plan_waypoints`) when ``settings.policy_len`` is 1, else
    :func:`~.drone_lookahead.plan_sequence` looking ``policy_len`` waypoints ahead.

    Parameters
    ----------
    model : DroneScene
        Position, target, perceived voxels, clearance, density, suitability, start distance,
        visited positions and the planner config.
    qs : sequence of numpy.ndarray
        The kernel beliefs (distance, azimuth, elevation first; their entropies are the epistemic
        term's ``H_d + H_az + H_el``).
    objective : Objective or None
        The EFE (:func:`~.drone_efe.drone_objective`); None builds it from the config's weights.
    settings : PlanSettings
        ``policy_len`` (the depth) and ``rng`` (the candidates' generator, required).

    Returns
    -------
    Plan
        ``action``: the ``(3,)`` waypoint to fly; ``G``: the EFE (one step) or sequence value of the
        returned waypoints, best first; ``policies``: those waypoints ``(K, 3)``; ``info``: the
        :class:`~.drone_planner.PlanResult`.

    Raises
    ------
    ValueError
        ``settings.rng`` is None or ``settings.policy_len`` < 1.
    """
    if settings.rng is None or settings.policy_len < 1:
        raise ValueError(f"drone_planner: needs settings.rng and policy_len >= 1, got rng={settings.rng!r}, "
                         f"policy_len={settings.policy_len}")
    m = model
    h = entropy(qs[0]) + entropy(qs[1]) + entropy(qs[2])
    args = (m.position, m.target, m.voxels, m.clearance, m.density, m.suitability, h, m.d_start, settings.rng,
            m.config)
    if settings.policy_len > 1:
        plan, G = plan_sequence(*args, LookaheadConfig(depth=settings.policy_len), m.visited, objective)
    else:
        plan = plan_waypoints(*args, m.visited, objective)
        G = plan.efe
    return Plan(plan.actions[0], np.asarray(G), None, plan.actions, plan)


BUILTIN = {"enumerate": enumerate_planner, "mcts": mcts_planner, "sophisticated": sophisticated_planner,
           "drone": drone_planner}
for _name, _accepts in (("enumerate", (Model, PlanningArrays)), ("mcts", (Model, PlanningArrays)),
                        ("sophisticated", (Model, PlanningArrays)), ("drone", DroneScene)):
    PLANNERS.add(_name, BUILTIN[_name], accepts=_accepts)
PLANNERS.seal()

__all__ = ["Plan", "PlanSettings", "accepting_planners", "available_planners", "drone_planner", "enumerate_planner",
           "get_planner", "mcts_planner", "register_planner", "sophisticated_planner", "unregister_planner"]

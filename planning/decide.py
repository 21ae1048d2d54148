"""One decision for an agent loop: model + belief + obstacle signal + mode -> action."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from . import efe
from .arrays import PlanningArrays, from_model, prepare
from .mcts import MCTSConfig, SearchResult, mcts
from .threads import limited

MODES = {"explore": efe.exploration, "goal": efe.goal, "full": efe.full, "sensed": efe.sensed_exploration,
         "pymdp": efe.pymdp_like}


def make_objective(mode, inductive_weight: float | None = None) -> efe.Objective:
    """The objective of a planning mode.

    Parameters
    ----------
    mode : str or Objective
        ``"explore"``, ``"goal"``, ``"full"``, ``"sensed"``, ``"pymdp"`` (keys of ``MODES``) or an
        :class:`~.efe.Objective`, returned as is.
    inductive_weight : float, optional
        Weight of the inductive term for ``"goal"``, ``"full"`` and ``"sensed"``; default the
        preset's.

    Returns
    -------
    Objective

    Raises
    ------
    ValueError
        For an unknown mode.
    """
    if isinstance(mode, efe.Objective):
        return mode
    if mode not in MODES:
        raise ValueError(f"unknown planning mode '{mode}' (known: {sorted(MODES)} or an Objective)")
    if mode in ("goal", "full", "sensed") and inductive_weight is not None:
        return MODES[mode](inductive_weight=inductive_weight)
    return MODES[mode]()


def check_plan_settings(policy_len, gamma, objective):
    """Check an agent's planning settings; returns the objective (a mode name made an Objective).

    Parameters
    ----------
    policy_len : int
        Steps per enumerated policy, an integer >= 1.
    gamma : float
        Policy precision, positive and finite.
    objective : Objective or str or None
        An Objective, a name of :data:`MODES`, or None.

    Returns
    -------
    Objective or None

    Raises
    ------
    ValueError
        For an invalid ``policy_len`` or ``gamma``, or an unknown objective name.
    """
    if not (isinstance(policy_len, int | np.integer) and policy_len >= 1):
        raise ValueError(f"policy_len must be an integer >= 1, got {policy_len!r}")
    if not (np.isfinite(gamma) and gamma > 0):
        raise ValueError(f"gamma (policy precision) must be positive and finite, got {gamma!r}")
    if isinstance(objective, str):
        if objective not in MODES:
            raise ValueError(f"unknown objective '{objective}' (known: {', '.join(MODES)} or an Objective)")
        objective = make_objective(objective)
    return objective


def decide(
    model,
    qs,
    obstacles=None,
    mode="explore",
    *,
    target_pose=None,
    goal_states=None,
    view=None,
    config: MCTSConfig | None = None,
    rng: np.random.Generator | int | None = None,
) -> SearchResult:
    """Choose the next control by MCTS over EFE.

    Parameters
    ----------
    model : Model or PlanningArrays
        A compiled model or planning arrays.
    qs : list of numpy.ndarray or numpy.ndarray
        Current belief, a list per factor or one ``(n,)`` array for a single factor.
    obstacles : array_like, optional
        One bool per control of the moving factor (True: obstacle in that direction).
    mode : str or Objective, optional
        ``"explore"`` (default), ``"goal"``, ``"full"``, ``"sensed"``, ``"pymdp"`` or a custom
        objective (:func:`make_objective`).
    target_pose : array_like, optional
        ``(2,)`` float target position in metres (position preference, inductive goal).
    goal_states : array_like, optional
        Int preferred states of the inductive term.
    view : array_like, optional
        Per state, the unseen fraction of its view in [0, 1] (read by ``efe.sensed_info_gain``).
    config : MCTSConfig, optional
        Search settings; default depth is the model's inductive depth, 30 simulations.
    rng : numpy.random.Generator or int or None, optional
        Random generator or seed.

    Returns
    -------
    SearchResult
    """
    if isinstance(model, PlanningArrays):
        arrays = model
        if target_pose is not None or goal_states is not None or view is not None:
            arrays = replace(
                arrays,
                target_pose=arrays.target_pose if target_pose is None else np.asarray(target_pose, float),
                goal_states=arrays.goal_states if goal_states is None else np.asarray(goal_states),
                view=arrays.view if view is None else np.asarray(view, float),
            )
        ind_w = None
    else:
        arrays = from_model(model, target_pose=target_pose, goal_states=goal_states, view=view)
        ind_w = None if model.inductive is None else float(model.inductive.weight)
    if isinstance(qs, np.ndarray) and qs.ndim == 1:
        qs = [qs]
    obj = make_objective(mode, ind_w)
    cfg = config or MCTSConfig(depth=arrays.inductive_depth)
    # a registered (user) term may read any attribute of the step context: prepare everything
    user = any(w != 0.0 and not efe.is_builtin(t) for t, w in obj.terms)
    prep = prepare(
        arrays,
        need_novelty=user or any(obj.uses(t) for t in (efe.param_info_gain, efe.a_novelty, efe.b_novelty,
                                                        efe.sensed_info_gain)),
        need_goal=user or obj.uses(efe.inductive),
    )
    with limited():
        return mcts(prep, qs, obj, obstacles, cfg, rng)

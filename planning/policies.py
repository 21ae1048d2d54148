"""Policy enumeration, EFE of policies by rolling beliefs forward (Eq. 5) and selection (Eq. 4)."""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import numpy as np

from cogmap.genmodel.numerics import softmax

from .action_selection import select_action
from .arrays import Prepared, as_arrays, prepare
from .context import DenseStep
from .efe import Objective
from .threads import limited


def enumerate_policies(
    num_controls: Sequence[int], length: int = 1, control_factors: Sequence[int] | None = None
) -> np.ndarray:
    """All policies of ``length`` steps (pymdp order: the last factor of the last step varies fastest).

    Parameters
    ----------
    num_controls : sequence of int
        Controls per factor.
    length : int, optional
        Steps per policy, default 1.
    control_factors : sequence of int, optional
        Factors whose controls vary; default those with more than one control. Others keep control 0.

    Returns
    -------
    numpy.ndarray
        ``(P, length, F)`` int controls.
    """
    F = len(num_controls)
    if control_factors is None:
        control_factors = [f for f, n in enumerate(num_controls) if n > 1]
    per_step = [range(num_controls[f]) if f in control_factors else range(1) for f in range(F)]
    combos = list(itertools.product(*(per_step * length)))
    return np.asarray(combos, dtype=np.int64).reshape(len(combos), length, F)


def obstacle_probability(obstacles, actions: np.ndarray, control_factor: int = 0) -> np.ndarray | None:
    """Collision probability per candidate from a per-control obstacle signal (bools or
    probabilities, one per control of ``control_factor``); ``None`` without a signal."""
    if obstacles is None:
        return None
    obs = np.asarray(obstacles, dtype=float)
    return obs[np.asarray(actions)[:, control_factor]]


def evaluate_policies(
    arrays,
    qs: Sequence[np.ndarray],
    policies: np.ndarray,
    objective: Objective,
    obstacles=None,
    per_step: bool = False,
) -> np.ndarray:
    """Expected free energy ``G(pi) = sum_tau G(pi, tau)`` of every policy, rolling beliefs forward.

    The obstacle signal applies to the first step only.

    Parameters
    ----------
    arrays : Model or PlanningArrays or Prepared
        The model (a :class:`Prepared` must be dense, ``local=False``).
    qs : sequence of numpy.ndarray
        Current belief per factor, ``(n_f,)`` float (or capacity length; trimmed to live states).
    policies : numpy.ndarray
        ``(P, T, F)`` int controls.
    objective : Objective
        Per-step EFE.
    obstacles : array_like, optional
        Per control of the control factor, bool or probability of an obstacle.
    per_step : bool, optional
        Also return the per-step values, default False.

    Returns
    -------
    G : numpy.ndarray
        ``(P,)`` float expected free energy (lower is better).
    steps : numpy.ndarray
        ``(P, T)`` float per-step values; only when ``per_step``.

    Raises
    ------
    ValueError
        If given a local (sparse-path) preparation.

    Notes
    -----
    Eq. (5) of the AIMAPP paper.
    """
    with limited():
        return _evaluate(arrays, qs, policies, objective, obstacles, per_step)


def _evaluate(arrays, qs, policies, objective, obstacles, per_step):
    prep = arrays if isinstance(arrays, Prepared) else prepare(as_arrays(arrays), local=False)
    if prep.local:
        raise ValueError("evaluate_policies needs a dense preparation (prepare(..., local=False))")
    a = prep.arrays
    policies = np.asarray(policies, dtype=np.int64)
    P, T, _ = policies.shape
    q = [np.broadcast_to(np.asarray(x, dtype=float)[: a.num_states[f]], (P, a.num_states[f])) for f, x in enumerate(qs)]
    steps = np.zeros((P, T))
    for t in range(T):
        coll = obstacle_probability(obstacles, policies[:, t], a.control_factor) if t == 0 else None
        ctx = DenseStep(prep, q, policies[:, t], t, coll)
        steps[:, t] = objective(ctx)
        q = ctx.qs
    G = steps.sum(axis=1)
    return (G, steps) if per_step else G


def policy_posterior(G: np.ndarray, gamma: float = 16.0, log_E: np.ndarray | None = None) -> np.ndarray:
    """Policy posterior ``q(pi) = softmax(-gamma G + ln E)``.

    Parameters
    ----------
    G : numpy.ndarray
        ``(P,)`` float expected free energy per policy.
    gamma : float, optional
        Precision, default 16.
    log_E : numpy.ndarray, optional
        ``(P,)`` float log prior over policies (habits).

    Returns
    -------
    numpy.ndarray
        ``(P,)`` float, sums to 1.

    Notes
    -----
    Eq. (4) of the AIMAPP paper.
    """
    x = -gamma * np.asarray(G, dtype=float)
    if log_E is not None:
        x = x + log_E
    return softmax(x)


def select(q: np.ndarray, rng: np.random.Generator | None = None) -> int:
    """Argmax of ``q`` (first on ties) or, with ``rng``, a sample from it.

    Parameters
    ----------
    q : numpy.ndarray
        ``(P,)`` float distribution.
    rng : numpy.random.Generator, optional
        Random generator; sample when given.

    Returns
    -------
    int
        The chosen index.
    """
    if rng is None:
        return int(np.argmax(q))
    return int(rng.choice(len(q), p=q))


def action_marginals(q: np.ndarray, policies: np.ndarray, num_controls: Sequence[int]) -> list[np.ndarray]:
    """Marginal probability of each first-step control per factor under ``q(pi)``."""
    return [
        np.bincount(policies[:, 0, f], weights=q, minlength=n) for f, n in enumerate(num_controls)
    ]


def infer_policies(
    arrays,
    qs: Sequence[np.ndarray],
    objective: Objective,
    length: int = 1,
    gamma: float = 16.0,
    obstacles=None,
    rng: np.random.Generator | None = None,
    log_E: np.ndarray | None = None,
    alpha: float = 1.0,
    sampling: str = "policy",
):
    """Enumerate, evaluate and pick a policy; returns its first action.

    Parameters
    ----------
    arrays : Model or PlanningArrays or Prepared
        The model.
    qs : sequence of numpy.ndarray
        Current belief per factor.
    objective : Objective
        Per-step EFE.
    length : int, optional
        Policy length, default 1.
    gamma : float, optional
        Policy precision, default 16.
    obstacles : array_like, optional
        Per-control obstacle signal (first step).
    rng : numpy.random.Generator, optional
        Sample the action instead of taking the mode.
    log_E : numpy.ndarray, optional
        ``(P,)`` float log habits over the enumerated policies (default: uniform).
    alpha : float, optional
        Action precision, default 1.
    sampling : str, optional
        ``"policy"`` (default: a policy, then its first step) or ``"marginal"`` (each factor's
        control from its marginal); see :mod:`~.action_selection`.

    Returns
    -------
    action : numpy.ndarray
        ``(F,)`` int first-step controls of the chosen policy.
    q_pi : numpy.ndarray
        ``(P,)`` float policy posterior.
    G : numpy.ndarray
        ``(P,)`` float expected free energies.
    policies : numpy.ndarray
        ``(P, length, F)`` int.
    """
    arrays = arrays if isinstance(arrays, Prepared) else as_arrays(arrays)
    a = arrays.arrays if isinstance(arrays, Prepared) else arrays
    policies = enumerate_policies(a.num_controls, length)
    G = evaluate_policies(arrays, qs, policies, objective, obstacles)
    q = policy_posterior(G, gamma, log_E)
    return select_action(q, policies, a.num_controls, alpha, sampling, rng), q, G, policies

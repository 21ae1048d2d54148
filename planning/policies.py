"""Policy enumeration, EFE of policies by rolling beliefs forward (Eq. 5) and selection (Eq. 4)."""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import numpy as np

from cogmap.genmodel.numerics import softmax

from .arrays import Prepared, as_arrays, prepare
from .context import DenseStep
from .efe import Objective
from .threads import limited


def enumerate_policies(
    num_controls: Sequence[int], length: int = 1, control_factors: Sequence[int] | None = None
) -> np.ndarray:
    """All policies of ``length`` steps, shape ``(P, length, F)`` (pymdp order: the last factor
    of the last step varies fastest). Factors not in ``control_factors`` (default: those with
    more than one control) keep control 0."""
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
    """Expected free energy ``G(pi) = sum_tau G(pi, tau)`` of every policy (Eq. 5), rolling
    the factor beliefs ``qs`` forward under each policy; ``per_step`` also returns ``(P, T)``.
    The obstacle signal applies to the first step."""
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
    """``q(pi) = softmax(-gamma G + ln E)`` (Eq. 4)."""
    x = -gamma * np.asarray(G, dtype=float)
    if log_E is not None:
        x = x + log_E
    return softmax(x)


def select(q: np.ndarray, rng: np.random.Generator | None = None) -> int:
    """Argmax of ``q`` (first on ties) or, with ``rng``, a sample from it."""
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
):
    """Enumerate, evaluate and pick: returns ``(first_action (F,), q_pi, G, policies)``.
    ``arrays`` is a compiled ``Model``, :class:`PlanningArrays` or a :class:`Prepared`."""
    arrays = arrays if isinstance(arrays, Prepared) else as_arrays(arrays)
    a = arrays.arrays if isinstance(arrays, Prepared) else arrays
    policies = enumerate_policies(a.num_controls, length)
    G = evaluate_policies(arrays, qs, policies, objective, obstacles)
    q = policy_posterior(G, gamma)
    i = select(q, rng)
    return policies[i, 0].copy(), q, G, policies

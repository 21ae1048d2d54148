"""Dirichlet learning of likelihoods and transitions.

Pure functions return new count arrays; :func:`learn_transition` and :func:`learn_observation`
apply the same updates in place to a growable :class:`~cogmap.genmodel.Model` (dense or sparse
transitions), keeping counts positive and columns normalised.

Transition learning rates depend on the event (Table 7 of the AIMAPP paper): an experienced
move counts more than a predicted one, and the reverse move is reinforced less than the
forward one. A negative rate removes counts from the move's target (floored so counts stay
positive) and adds them to staying in place, which is what a blocked move is evidence of; a
column's total concentration is capped so that beliefs reinforced many times can still change
when the world does (a moved obstacle).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

import numpy as np

from cogmap.genmodel.dirichlet import normalise_counts, update_pA  # noqa: F401 - the pure updates, re-exported
from cogmap.genmodel.model import Model
from cogmap.genmodel.spec import SpecError


class Event(Enum):
    """What the agent learnt about a transition."""

    POSSIBLE = "possible"  # experienced: the move reached the state
    IMPOSSIBLE = "impossible"  # experienced: the move was blocked
    PREDICTED_POSSIBLE = "predicted_possible"  # sensed free space towards the state
    PREDICTED_IMPOSSIBLE = "predicted_impossible"  # sensed an obstacle towards the state


@dataclass(frozen=True)
class LearningRates:
    """Table 7: forward 7 / -7 / 5 / -5, reverse 5 / -5 / 3 / -3."""

    forward: tuple[float, float, float, float] = (7.0, -7.0, 5.0, -5.0)
    reverse: tuple[float, float, float, float] = (5.0, -5.0, 3.0, -3.0)
    floor: float = 1e-3  # counts never fall below this (they must stay positive)
    max_concentration: float = 10.0  # a column's counts are scaled down past this (forgetting)

    def rate(self, event: Event, reverse: bool = False) -> float:
        order = (Event.POSSIBLE, Event.IMPOSSIBLE, Event.PREDICTED_POSSIBLE, Event.PREDICTED_IMPOSSIBLE)
        return (self.reverse if reverse else self.forward)[order.index(event)]


TABLE7 = LearningRates()


# -- pure updates ------------------------------------------------------------------------------
def update_pB(pB: np.ndarray, q_next, q_prev, control: int, lr: float = 1.0, floor: float = 1e-3) -> np.ndarray:
    """``pB[:, :, u] + lr * q(s_t) (x) q(s_t-1)`` with counts floored at ``floor`` (Eq. 8)."""
    pB = np.array(pB, dtype=float)
    q_next, q_prev = np.asarray(q_next, dtype=float), np.asarray(q_prev, dtype=float)
    if pB.shape[:2] != (q_next.size, q_prev.size):
        raise SpecError(f"update_pB: beliefs of sizes {q_next.size}, {q_prev.size} do not match pB {pB.shape}")
    touched = np.outer(q_next, q_prev) > 0
    col = pB[:, :, control] + lr * np.outer(q_next, q_prev)
    pB[:, :, control] = np.where(touched, np.maximum(col, floor), col)
    return pB


# -- in-place updates on a model ---------------------------------------------------------------
def learn_transition(
    model: Model,
    factor: int,
    s_from: int,
    control: int,
    s_to: int,
    event: Event,
    reverse_control: int | None = None,
    rates: LearningRates = TABLE7,
) -> None:
    """Dirichlet update of the transition ``s_from --control--> s_to`` for ``event``.

    With ``reverse_control`` the reverse move ``s_to --reverse_control--> s_from`` is updated
    with the reverse rate. The structural stay control is never learned.
    """
    f = model.factor_index(factor)
    n = model.num_states[f]
    for s in (s_from, s_to):
        if not 0 <= s < n:
            raise SpecError(f"learn_transition: state {s} is not live (factor has {n} states)")
    updates = [(s_from, control, s_to, rates.rate(event))]
    if reverse_control is not None:
        updates.append((s_to, reverse_control, s_from, rates.rate(event, reverse=True)))
    stay = model.factors[f].stay
    for a, u, b, lr in updates:
        if not 0 <= u < model.factors[f].num_controls:
            raise SpecError(f"learn_transition: control {u} out of range")
        if u == stay:
            continue
        B = model.B[f]
        if B.counts is None:
            raise SpecError(f"learn_transition: factor '{model.factors[f].name}' has no pB counts")
        B.learn(a, u, b, lr, n, rates.floor, rates.max_concentration)


def learn_observation(model: Model, modality: int, obs: int, qs: list[np.ndarray], lr: float = 1.0) -> None:
    """Dirichlet update of ``A[modality]`` towards ``obs`` under beliefs ``qs`` (live slices)."""
    m = model.modality_index(modality)
    if not model.has_counts_A(m):
        raise SpecError(f"learn_observation: modality '{model.modalities[m].name}' has no pA counts")
    deps = model.A_deps[m]
    model.A[m].learn(obs, [np.asarray(qs[f], dtype=float)[: model.num_states[f]] for f in deps], lr)

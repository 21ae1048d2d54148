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

from cogmap.genmodel.model import Model
from cogmap.genmodel.spec import SpecError
from cogmap.genmodel.transitions import SparseTransitions


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
def update_pA(pA: np.ndarray, obs, qs: list[np.ndarray], lr: float = 1.0, floor: float = 1e-3) -> np.ndarray:
    """``pA + lr * o (x) q(s_deps)`` for one modality; ``obs`` is an index or a distribution."""
    pA = np.asarray(pA, dtype=float)
    o = _as_distribution(obs, pA.shape[0])
    outer = o
    for q in qs:
        outer = np.multiply.outer(outer, np.asarray(q, dtype=float))
    if outer.shape != pA.shape:
        raise SpecError(f"update_pA: outer product shape {outer.shape} does not match pA {pA.shape}")
    new = pA + lr * outer
    return np.where(outer > 0, np.maximum(new, floor), new)


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


def normalise_counts(p: np.ndarray) -> np.ndarray:
    """Expected parameters of Dirichlet counts (columns over the first axis)."""
    s = p.sum(axis=0, keepdims=True)
    return np.where(s > 0, p / np.where(s > 0, s, 1.0), 1.0 / p.shape[0])


def _as_distribution(obs, n: int) -> np.ndarray:
    if np.ndim(obs) == 0:
        o = int(obs)
        if not 0 <= o < n:
            raise SpecError(f"observation {o} out of range [0, {n})")
        v = np.zeros(n)
        v[o] = 1.0
        return v
    v = np.asarray(obs, dtype=float)
    if v.shape != (n,):
        raise SpecError(f"observation distribution has shape {v.shape}, expected ({n},)")
    return v


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
        if isinstance(B, SparseTransitions):
            _learn_sparse(B, a, u, b, lr, rates)
        else:
            _learn_dense(model, f, a, u, b, lr, rates)


def _learn_sparse(B: SparseTransitions, s: int, u: int, target: int, lr: float, rates: LearningRates) -> None:
    if B.counts is None:
        raise SpecError("learn_transition: transitions have no Dirichlet counts")
    if lr < 0 and B.slot_of(s, u, target, create=False) < 0:
        return  # nothing believed to remove
    k = B.slot_of(s, u, target)
    B.counts[s, u, k] = max(B.counts[s, u, k] + lr, rates.floor)
    if lr < 0:
        B.counts[s, u, B.slot_of(s, u, s)] += -lr
    total = B.counts[s, u].sum()
    if total > rates.max_concentration:
        B.counts[s, u] *= rates.max_concentration / total
    B.renormalise_column(s, u)


def _learn_dense(model: Model, f: int, s: int, u: int, target: int, lr: float, rates: LearningRates) -> None:
    pB = model.pB[f]
    if pB is None:
        raise SpecError(f"learn_transition: factor '{model.factors[f].name}' has no pB counts")
    n = model.num_states[f]
    pB[target, s, u] = max(pB[target, s, u] + lr, rates.floor)
    if lr < 0:
        pB[s, s, u] += -lr
    col = pB[:n, s, u]
    total = col.sum()
    if total > rates.max_concentration:
        col *= rates.max_concentration / total
        total = rates.max_concentration
    model.B[f][:n, s, u] = col / total


def learn_observation(model: Model, modality: int, obs: int, qs: list[np.ndarray], lr: float = 1.0) -> None:
    """Dirichlet update of ``A[modality]`` towards ``obs`` under beliefs ``qs`` (live slices)."""
    m = model.modality_index(modality)
    if not model.has_counts_A(m):
        raise SpecError(f"learn_observation: modality '{model.modalities[m].name}' has no pA counts")
    deps = model.A_deps[m]
    if model.is_sparse_A(m):
        if not isinstance(obs, int | np.integer):
            raise SpecError("learn_observation: a sparse likelihood learns from an outcome index")
        model.A[m].learn(int(obs), np.asarray(qs[deps[0]])[: model.num_states[deps[0]]], lr)
        return
    deps_q = [np.asarray(qs[f])[: model.num_states[f]] for f in deps]
    n_o = model.num_obs[m]
    if len(deps) == 1:  # touch only the columns the belief reaches: O(outcomes x support)
        cols = np.flatnonzero(deps_q[0] > 0)
        o = _as_distribution(obs, n_o)
        block = model.pA[m][:n_o, cols] + lr * np.outer(o, deps_q[0][cols])
        block = np.where(o[:, None] > 0, np.maximum(block, 1e-3), block)
        model.pA[m][:n_o, cols] = block
        model.A[m][:n_o, cols] = normalise_counts(block)
        return
    live = (slice(0, n_o),) + tuple(slice(0, model.num_states[f]) for f in deps)
    new = update_pA(model.pA[m][live], obs, deps_q, lr)
    model.pA[m][live] = new
    model.A[m][live] = normalise_counts(new)

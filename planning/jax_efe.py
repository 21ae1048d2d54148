"""Expected free energy of enumerated policies as pure JAX functions (jit, vmap and grad through them).

The terms that apply to dense discrete models, with the numpy terms' definitions and signs
(:mod:`cogmap.planning.efe`): utility (``observation_preference``), state information gain,
parameter information gain about ``A`` and ``B`` (``a_novelty``, ``b_novelty``), the preference
over states and the inductive term (Eq. 9 of the AIMAPP paper). Their weights are an array
pytree (:class:`EFEWeights`), so they can be fitted. ``G(pi) = -sum_tau sum_i w_i term_i``;
``q(pi) = softmax(-gamma G)`` (Eq. 4); the action distribution is the marginal of ``q(pi)``
over the first step's controls.
"""

from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np
from jax.scipy.special import digamma

from cogmap.genmodel.numerics import LOG_FLOOR
from cogmap.genmodel.numerics import xlogx_jax as xlogx

from . import efe as np_efe
from .inductive import UNREACHABLE


class EFEWeights(NamedTuple):
    """Weight of each EFE term (a pytree of scalars: fit them, batch them).

    Attributes
    ----------
    utility, state_info_gain, a_novelty, b_novelty, state_preference, inductive : float
        Weights of ``observation_preference``, ``state_info_gain``, ``a_novelty``, ``b_novelty``,
        ``state_preference`` and ``inductive`` (:mod:`cogmap.planning.efe`).
    """

    utility: float = 1.0
    state_info_gain: float = 1.0
    a_novelty: float = 0.0
    b_novelty: float = 0.0
    state_preference: float = 0.0
    inductive: float = 0.0


_TERM_FIELDS = {
    np_efe.observation_preference: ("utility",),
    np_efe.state_info_gain: ("state_info_gain",),
    np_efe.a_novelty: ("a_novelty",),
    np_efe.b_novelty: ("b_novelty",),
    np_efe.param_info_gain: ("a_novelty", "b_novelty"),
    np_efe.state_preference: ("state_preference",),
    np_efe.inductive: ("inductive",),
}


def weights_of(objective) -> EFEWeights:
    """The weights of a numpy :class:`~cogmap.planning.efe.Objective` made of the terms above.

    Parameters
    ----------
    objective : Objective

    Returns
    -------
    EFEWeights

    Raises
    ------
    ValueError
        For a term the JAX backend does not have (collision, position and sensed terms need the
        robot's sensors and poses: use the numpy backend).
    """
    w = dict.fromkeys(EFEWeights._fields, 0.0)
    for term, weight in objective.terms:
        fields = _TERM_FIELDS.get(term)
        if fields is None:
            name = getattr(term, "__name__", repr(term))
            raise ValueError(f"the JAX backend has no EFE term '{name}' (it has "
                             f"{', '.join(sorted(t.__name__ for t in _TERM_FIELDS))}); use the numpy backend")
        for f in fields:
            w[f] += float(weight)
    return EFEWeights(**w)


def goal_distances_of(model, goal_states=None) -> np.ndarray | None:
    """Steps from each state of the goal factor to the nearest goal state, as the numpy planner
    counts them (``inf`` beyond the inductive horizon), at the factor's capacity; None without a goal.

    Parameters
    ----------
    model : Model
    goal_states : array_like, optional
        Int goal states; default the numpy planner's (states of maximal positive ``C_states``).

    Returns
    -------
    numpy.ndarray or None
        ``(capacity,)`` float, for :func:`cogmap.genmodel.jax_model.to_jax`'s ``goal_dist``.
    """
    from .arrays import from_model
    from .inductive import goal_distances

    pa = from_model(model, goal_states=goal_states)
    if pa.goal_states is None or not len(pa.goal_states):
        return None
    g = pa.goal_factor
    n = model.num_states[g]
    src, dst = model.B[g].edges(pa.inductive_threshold, n)
    d = goal_distances(src, dst, pa.goal_states, n, pa.inductive_depth).astype(float)
    d[d >= UNREACHABLE] = np.inf
    full = np.full(model.B[g].prob.shape[0], np.inf)
    full[:n] = d
    return full


class Prepared(NamedTuple):
    """Per-model quantities of every decision: column entropies and novelty weights.

    Attributes
    ----------
    HA : tuple of jax.Array
        Per modality, the entropy (nats) of each column of ``A``.
    wA : tuple
        Per modality, novelty weights of ``pA`` (or None).
    wB : tuple
        Per factor, novelty weights of ``pB`` (or None).
    """

    HA: tuple
    wA: tuple
    wB: tuple


def novelty_weights(counts):
    """``ln a0 - ln a + psi(a + 1) - psi(a0 + 1)`` of Dirichlet ``counts`` (columns over axis 0), 0
    where a count is 0 (numpy :func:`~cogmap.planning.efe.novelty_weights`)."""
    a = jnp.maximum(counts, LOG_FLOOR)
    a0 = jnp.maximum(jnp.sum(a, axis=0, keepdims=True), LOG_FLOOR)
    w = jnp.log(a0) - jnp.log(a) + digamma(a + 1.0) - digamma(a0 + 1.0)
    return jnp.where(counts > 0, w, 0.0)


def prepare(arrays) -> Prepared:
    """Column entropies of ``A`` and novelty weights of the counts."""
    return Prepared(
        tuple(-jnp.sum(xlogx(a), axis=0) for a in arrays.A),
        tuple(None if p is None else novelty_weights(p) for p in arrays.pA),
        tuple(None if p is None else novelty_weights(p) for p in arrays.pB),
    )


def _expect(x, deps, qs, keep_outcomes: bool):
    """``x`` contracted with per-candidate beliefs ``qs[f]`` ``(K, n_f)``: ``(K, o)`` or ``(K,)``."""
    lead = 1 if keep_outcomes else 0
    k = lead + len(deps)  # the label of the candidate axis
    args = [x, list(range(k))]
    for i, f in enumerate(deps):
        args += [qs[f], [k, lead + i]]
    return jnp.einsum(*args, [k, 0] if keep_outcomes else [k])


def _predict(B, q_prev, u, first: bool):
    """``B[:, :, u_k] q_prev[k]`` per candidate; on the first step every candidate starts from the
    same belief, so each control is applied once and the results are picked (no copy of ``B``
    per candidate)."""
    if first:
        return jnp.einsum("iju,j->ui", B, q_prev[0])[u]
    return jnp.einsum("ijk,kj->ki", B[:, :, u], q_prev)


def step_values(layout, arrays, prep: Prepared, weights: EFEWeights, q_prev, actions, first: bool = False):
    """One imagined step of ``K`` candidates: ``(G_step (K,), predicted beliefs)``.

    Parameters
    ----------
    layout, arrays
        The model.
    prep : Prepared
    weights : EFEWeights
    q_prev : tuple of jax.Array
        Per factor ``(K, capacity[f])`` beliefs before the step.
    actions : jax.Array
        ``(K, F)`` int controls.
    first : bool, optional
        Whether every candidate starts from the same belief (the first step of a policy).
    """
    qs = tuple(_predict(arrays.B[f], q_prev[f], actions[:, f], first) for f in range(layout.num_factors))
    K = actions.shape[0]
    value = jnp.zeros(K, dtype=qs[0].dtype)
    for m, deps in enumerate(layout.A_deps):
        qo = _expect(arrays.A[m], deps, qs, True)
        h = -jnp.sum(xlogx(qo), axis=1)
        amb = _expect(prep.HA[m], deps, qs, False)
        value = value + weights.state_info_gain * (h - amb) + weights.utility * (qo @ arrays.C[m])
        if prep.wA[m] is not None:
            ew = _expect(prep.wA[m], deps, qs, True)
            value = value + weights.a_novelty * jnp.sum(qo * ew, axis=1)
    for f in range(layout.num_factors):
        if prep.wB[f] is not None:
            w = prep.wB[f][:, :, actions[:, f]]
            value = value + weights.b_novelty * jnp.einsum("ki,ijk,kj->k", qs[f], w, q_prev[f])
        value = value + weights.state_preference * (qs[f] @ arrays.C_states[f])
    if arrays.goal_dist is not None:
        g, d = layout.goal_factor, arrays.goal_dist
        d_prev = d[jnp.argmax(q_prev[g], axis=1)]
        good = (d[None, :] < d_prev[:, None]) | (d[None, :] == 0)
        closer = jnp.where(d_prev <= layout.inductive_depth, jnp.sum(qs[g] * good, axis=1), 0.0)
        value = value + weights.inductive * closer
    return -value, qs


def policy_efe(layout, arrays, prep: Prepared, weights: EFEWeights, qs, policies):
    """``G(pi)`` of every policy, rolling the beliefs forward (Eq. 5).

    Parameters
    ----------
    layout, arrays, prep, weights
        The model, its prepared quantities and the term weights.
    qs : tuple of jax.Array
        ``(capacity[f],)`` current belief per factor.
    policies : jax.Array
        ``(P, T, F)`` int.

    Returns
    -------
    jax.Array
        ``(P,)`` expected free energy per policy (lower is better).
    """
    P, T, _ = policies.shape
    q = tuple(jnp.broadcast_to(x, (P, x.shape[0])) for x in qs)
    G = jnp.zeros(P, dtype=qs[0].dtype)
    for t in range(T):
        g, q = step_values(layout, arrays, prep, weights, q, policies[:, t], first=t == 0)
        G = G + g
    return G


def action_distribution(q_pi, policies: np.ndarray, num_controls, alpha=1.0, sampling: str = "policy") -> jax.Array:
    """Probability of each first-step control combination, shaped ``num_controls``: what a sampling
    agent draws from with action precision ``alpha`` (the JAX form of
    :func:`cogmap.planning.action_selection.control_probabilities`)."""
    policies = np.asarray(policies)
    shape = tuple(int(u) for u in num_controls)
    if sampling == "marginal":
        out = jnp.ones(())
        for f, n in enumerate(shape):  # factors drawn independently from softmax(alpha ln q(u_f))
            m = jax.ops.segment_sum(q_pi, jnp.asarray(policies[:, 0, f]), num_segments=n)
            out = jnp.multiply.outer(out, jax.nn.softmax(alpha * jnp.log(jnp.maximum(m, LOG_FLOOR))))
        return out
    w = jax.nn.softmax(alpha * jnp.log(jnp.maximum(q_pi, LOG_FLOOR)))
    idx = np.ravel_multi_index(tuple(policies[:, 0, f] for f in range(len(shape))), shape)
    flat = jax.ops.segment_sum(w, jnp.asarray(idx), num_segments=int(np.prod(shape)))
    return flat.reshape(shape)


def choose_action(key, q_pi, policies: np.ndarray, num_controls, alpha=1.0, sampling: str = "policy",
                  sample: bool = True) -> jax.Array:
    """``(F,)`` int first-step controls: drawn with ``key`` when ``sample``, else the mode (the JAX
    form of :func:`cogmap.planning.action_selection.select_action`)."""
    policies = np.asarray(policies)
    shape = tuple(int(u) for u in num_controls)
    if sampling == "marginal":
        if sample:
            p = action_distribution(q_pi, policies, shape, alpha, sampling)
            i = jax.random.categorical(key, jnp.log(jnp.maximum(p.reshape(-1), 1e-300)))
            return jnp.stack(jnp.unravel_index(i, shape)).astype(jnp.int32)
        return jnp.stack([jnp.argmax(jax.ops.segment_sum(q_pi, jnp.asarray(policies[:, 0, f]), num_segments=n))
                          for f, n in enumerate(shape)]).astype(jnp.int32)
    if sample:
        i = jax.random.categorical(key, alpha * jnp.log(jnp.maximum(q_pi, LOG_FLOOR)))
    else:
        i = jnp.argmax(q_pi)
    return jnp.asarray(policies)[i, 0].astype(jnp.int32)


__all__ = ["EFEWeights", "Prepared", "action_distribution", "choose_action", "goal_distances_of", "novelty_weights",
           "policy_efe", "prepare", "step_values", "weights_of"]

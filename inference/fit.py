"""Learning A and/or B from observation-action sequences (variational Bayes EM).

For a model with one hidden factor and Dirichlet counts ``pA`` / ``pB`` (the prior), each
iteration alternates

1. *smoothing*: exact forward-backward over every sequence under the geometric-mean
   parameters ``exp(E[log A])``, ``exp(E[log B])`` of the current posterior counts, giving the
   state marginals ``q(s_t)`` and the pairwise ``q(s_t-1, s_t)``;
2. *Dirichlet update* (Eq. 8 with the expected counts of the whole data): ``a = a0 + sum_t
   o_t (x) q(s_t)``, ``b[:, :, u] = b0[:, :, u] + sum_{t: u_t-1 = u} q(s_t, s_t-1)``.

The free energy reported for iteration ``k`` is that of the posterior over states and
parameters after its smoothing step::

    F_k = - sum_sequences log Z(exp E[log A], exp E[log B]) + KL(q(A) || p(A)) + KL(q(B) || p(B))

and never increases from one iteration to the next (each step minimises F over one block of
the posterior with the other fixed). With the learned counts the model's ``A`` / ``B`` become
their expected values.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
from scipy.special import digamma, gammaln

from cogmap.genmodel.numerics import TINY_FLOOR, floor_log
from cogmap.genmodel.spec import SpecError

from .bayes_filter import bayes_filter


class FitResult(NamedTuple):
    free_energy: list  # F after the smoothing step of each iteration (nats), non-increasing
    iterations: int


def _kl_dirichlet(a: np.ndarray, a0: np.ndarray) -> float:
    """Sum over columns (axis 0) of KL(Dir(a) || Dir(a0))."""
    s, s0 = a.sum(axis=0), a0.sum(axis=0)
    return float(np.sum(gammaln(s) - gammaln(s0) - np.sum(gammaln(a) - gammaln(a0), axis=0)
                        + np.sum((a - a0) * (digamma(a) - digamma(s)[None]), axis=0)))


def _elog(counts: np.ndarray) -> np.ndarray:
    return digamma(counts) - digamma(counts.sum(axis=0, keepdims=True))


def _forward_backward(lik: np.ndarray, trans: list[np.ndarray], actions: np.ndarray, d: np.ndarray):
    """Scaled forward-backward with (sub-normalised) ``lik`` (T, n) and ``trans[u]`` (n, n);
    returns (gamma (T, n), pairwise sums per control (u, n, n) [next, prev], log Z)."""
    T, n = lik.shape
    alpha = np.empty((T, n))
    c = np.empty(T)
    a = d * lik[0]
    c[0] = a.sum()
    alpha[0] = a / c[0]
    for t in range(1, T):
        a = lik[t] * (trans[actions[t - 1]] @ alpha[t - 1])
        c[t] = a.sum()
        alpha[t] = a / c[t]
    beta = np.ones(n)
    gamma = np.empty((T, n))
    gamma[-1] = alpha[-1]
    xi = np.zeros((len(trans), n, n))
    for t in range(T - 1, 0, -1):
        B = trans[actions[t - 1]]
        w = lik[t] * beta  # (n,) next
        xi[actions[t - 1]] += (w[:, None] * B * alpha[t - 1][None, :]) / c[t]
        beta = (B.T @ w) / c[t]
        gamma[t - 1] = alpha[t - 1] * beta
    return gamma, xi, float(np.log(c).sum())


def fit(model, sequences: Sequence, *, learn_A: bool = True, learn_B: bool = True, iterations: int = 20,
        tol: float = 1e-6, init_counts: float = 0.0, seed: int | None = None) -> FitResult:
    """Fit the Dirichlet counts of ``model`` (one factor, dense) to ``sequences``, each a pair
    ``(observations, actions)`` with ``observations[t]`` one outcome index per modality and
    ``actions[t]`` the control between steps ``t`` and ``t + 1``. The model's current counts
    are the prior. Stops after ``iterations`` or when F improves by less than ``tol`` (relative).

    Hidden states that look alike are exchangeable under a flat prior, so EM started at the
    prior stays in the symmetric solution; ``init_counts > 0`` starts the posterior at the prior
    plus random counts (exponential, mean ``init_counts``, seeded by ``seed``) to break it."""
    if len(model.factors) != 1 or model.is_sparse(0) or any(model.is_sparse_A(m) for m in range(len(model.modalities))):
        raise SpecError("fit needs a model with one hidden factor and dense factors")
    if not (learn_A or learn_B):
        raise ValueError("nothing to learn: set learn_A and/or learn_B")
    if learn_A and not all(model.has_counts_A(m) for m in range(len(model.modalities))):
        raise SpecError("fit(learn_A=True) needs Dirichlet counts (pA) for every modality")
    if learn_B and model.B[0].counts is None:
        raise SpecError("fit(learn_B=True) needs Dirichlet counts (pB)")
    if iterations < 1:
        raise ValueError(f"iterations must be >= 1, got {iterations}")
    n, U, M = model.num_states[0], model.num_controls[0], len(model.modalities)
    data = []
    for k, (obs, acts) in enumerate(sequences):
        obs = np.asarray(obs, dtype=np.int64).reshape(len(obs), M)
        acts = np.asarray(acts, dtype=np.int64).reshape(-1)
        if acts.size != len(obs) - 1:
            raise ValueError(f"sequence {k}: {len(obs)} observations need {len(obs) - 1} actions, got {acts.size}")
        if acts.size and (acts.min() < 0 or acts.max() >= U):
            raise ValueError(f"sequence {k}: an action is outside 0..{U - 1}")
        for m in range(M):
            if obs[:, m].min() < 0 or obs[:, m].max() >= model.num_obs[m]:
                raise ValueError(f"sequence {k}: an outcome of modality {m} is outside 0..{model.num_obs[m] - 1}")
        data.append((obs, acts))
    a0 = [model.live_pA(m).copy() if learn_A else None for m in range(M)]
    b0 = model.live_pB(0).copy() if learn_B else None
    rng = np.random.default_rng(seed)
    a = [None if x is None else x + rng.exponential(init_counts, x.shape) for x in a0]
    b = None if b0 is None else b0 + rng.exponential(init_counts, b0.shape)
    d = model.live_D(0)
    history: list[float] = []
    for _ in range(iterations):
        logA = [_elog(a[m]) if learn_A else floor_log(model.live_A(m), TINY_FLOOR) for m in range(M)]
        trans = ([np.exp(_elog(b[:, :, u])) for u in range(U)] if learn_B
                 else [model.live_B(0)[:, :, u] for u in range(U)])
        F = 0.0
        new_a = [None if x is None else x.copy() for x in a0]
        new_b = None if b0 is None else b0.copy()
        for obs, acts in data:
            lik = np.exp(sum(logA[m][obs[:, m]] for m in range(M)))
            gamma, xi, log_z = _forward_backward(lik, trans, acts, d)
            F -= log_z
            if learn_A:
                for m in range(M):
                    np.add.at(new_a[m], obs[:, m], gamma)
            if learn_B:
                new_b += np.moveaxis(xi, 0, 2)
        if learn_A:
            F += sum(_kl_dirichlet(a[m], a0[m]) for m in range(M))
        if learn_B:
            F += sum(_kl_dirichlet(b[:, :, u], b0[:, :, u]) for u in range(U))
        history.append(F)
        a, b = new_a, new_b
        if len(history) > 1 and history[-2] - history[-1] < tol * abs(history[-1]):
            break
    for m in range(M):  # live views of the dense factors, written in place
        if learn_A:
            model.A[m].counts_dense()[...] = a[m]
            model.A[m].to_dense()[...] = a[m] / a[m].sum(axis=0, keepdims=True)
    if learn_B:
        model.B[0].counts_dense(n)[...] = b
        model.B[0].to_dense(n)[...] = b / b.sum(axis=0, keepdims=True)
    return FitResult(history, len(history))


def surprise_bits(model, observations, actions) -> float:
    """Mean predictive surprise ``-log2 p(o_t | o_<t, u_<t)`` per step under the model's
    expected parameters (one factor): the exact filter's ``-log p(o_1:T)`` over ``T ln 2``."""
    actions = [(int(a),) for a in np.asarray(actions, dtype=np.int64).reshape(-1)]
    _, info = bayes_filter(model, [model.live_D(0)], [list(o) for o in observations], actions)
    return info.total_free_energy / (len(observations) * np.log(2.0))

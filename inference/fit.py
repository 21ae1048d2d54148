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

EM stops in local optima when places are aliased; :func:`fit` offers seeded restarts (kept by
lowest F) and deterministic annealing against them. Restarts run together: one batched
forward-backward for all of them.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
from scipy.linalg import block_diag
from scipy.special import digamma, gammaln
from threadpoolctl import threadpool_limits

from cogmap.genmodel.numerics import TINY_FLOOR, floor_log
from cogmap.genmodel.spec import SpecError

from .bayes_filter import bayes_filter


class FitResult(NamedTuple):
    free_energy: list  # F after the smoothing step of each iteration at temperature 1 (nats), kept restart
    iterations: int  # iterations of the kept restart, annealing included
    restart_free_energy: list  # final F of every restart; the kept one is the lowest
    histories: list  # per restart, F of each iteration at temperature 1 (each non-increasing)
    best: int  # index of the kept restart


def _kl_dirichlet(a: np.ndarray, a0: np.ndarray) -> np.ndarray:
    """``KL(Dir(a) || Dir(a0))`` for a batch of counts ``(R, ..., outcomes, columns)``, summed
    over the columns of each restart: shape ``(R,)``."""
    s, s0 = a.sum(axis=-2), a0.sum(axis=-2)
    kl = (gammaln(s) - gammaln(s0) - np.sum(gammaln(a) - gammaln(a0), axis=-2)
          + np.sum((a - a0) * (digamma(a) - digamma(s)[..., None, :]), axis=-2))
    return kl.reshape(kl.shape[0], -1).sum(axis=1)


def _elog(counts: np.ndarray, axis: int = 0) -> np.ndarray:
    return digamma(counts) - digamma(counts.sum(axis=axis, keepdims=True))


_BLOCK = 128  # restarts are smoothed together in groups of at most this many states in all (past
# that the wasted products of the block-diagonal matrix cost more than the steps it saves)


def _forward_backward_batch(lik: np.ndarray, trans: np.ndarray, actions: np.ndarray, d: np.ndarray):
    """Scaled forward-backward for ``R`` models at once (the restarts share the data):
    ``lik`` (R, T, n) sub-normalised likelihoods, ``trans`` (R, U, n, n) [next, prev], ``d`` (R, n).
    Returns (gamma (R, T, n), pairwise sums per control (R, U, n, n) [next, prev], log Z (R,))."""
    R, _, n = lik.shape
    k = max(1, _BLOCK // n)
    parts = [_forward_backward_block(lik[i:i + k], trans[i:i + k], actions, d[i:i + k]) for i in range(0, R, k)]
    return tuple(np.concatenate(x) for x in zip(*parts, strict=True))


def _forward_backward_block(lik, trans, actions, d):
    """:func:`_forward_backward_batch` for a few models stacked into one block-diagonal chain of
    ``R n`` states, so that each step is one matrix-vector product whatever ``R``. The pairwise
    expectations ``sum_t q(s_t, s_t-1)`` are summed per control after the loops as one matrix
    product ``(lik_t beta_t / c_t)^T alpha_t-1`` times ``B_u`` (Rabiner 1989, Eq. 37)."""
    R, T, n = lik.shape
    U = trans.shape[1]
    fwd = [block_diag(*trans[:, u]) for u in range(U)]
    L = np.ascontiguousarray(lik.transpose(1, 0, 2)).reshape(T, R * n)
    alpha = np.empty((T, R * n))
    c = np.empty((T, R))
    a = (d * lik[:, 0]).reshape(-1)
    for t in range(T):
        if t:
            a = L[t] * (fwd[actions[t - 1]] @ alpha[t - 1])
        a = a.reshape(R, n)
        c[t] = a.sum(axis=1)
        np.divide(a, c[t, :, None], out=alpha[t].reshape(R, n))
    bwd = [np.ascontiguousarray(b.T) for b in fwd]
    w = (L.reshape(T, R, n) / c[:, :, None]).reshape(T, R * n)  # lik_t / c_t, then times beta_t
    beta = np.empty((T, R * n))
    beta[-1] = 1.0
    for t in range(T - 1, 0, -1):
        w[t] *= beta[t]
        np.matmul(bwd[actions[t - 1]], w[t], out=beta[t - 1])
    gamma = (alpha * beta).reshape(T, R, n).transpose(1, 0, 2)
    xi = np.empty((R, U, n, n))
    blocks = np.arange(R)
    for u in range(U):
        idx = np.flatnonzero(actions == u) + 1
        pair = (w[idx].T @ alpha[idx - 1]).reshape(R, n, R, n)  # every restart against every other
        xi[:, u] = pair[blocks, :, blocks] * trans[:, u]  # keep the diagonal blocks
    return gamma, xi, np.log(c).sum(axis=0)


def _forward_backward(lik: np.ndarray, trans: list[np.ndarray], actions: np.ndarray, d: np.ndarray):
    """One model: ``lik`` (T, n), ``trans[u]`` (n, n); returns (gamma (T, n), pairwise sums per
    control (U, n, n) [next, prev], log Z)."""
    gamma, xi, log_z = _forward_backward_batch(lik[None], np.stack(trans)[None], np.asarray(actions), d[None])
    return gamma[0], xi[0], float(log_z[0])


def _temper(counts: np.ndarray, beta: float) -> np.ndarray:
    """Dirichlet counts at inverse temperature ``beta``: ``beta (counts - 1) + 1`` (Katahira et
    al. 2008), the flat Dirichlet at ``beta = 0`` and the counts themselves at ``beta = 1``."""
    return counts if beta == 1.0 else beta * (counts - 1.0) + 1.0


def _check_sequences(model, sequences) -> list[tuple[np.ndarray, np.ndarray]]:
    U, M = model.num_controls[0], len(model.modalities)
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
    return data


def fit(model, sequences: Sequence, *, learn_A: bool = True, learn_B: bool = True, iterations: int = 20,
        tol: float = 1e-6, init_counts: float = 0.0, seed: int | None = None, restarts: int = 1,
        anneal_iterations: int = 0, anneal_from: float = 0.7) -> FitResult:
    """Fit the Dirichlet counts of ``model`` (one factor, dense) to ``sequences``, each a pair
    ``(observations, actions)`` with ``observations[t]`` one outcome index per modality and
    ``actions[t]`` the control between steps ``t`` and ``t + 1``. The model's current counts
    are the prior. Each restart stops after ``iterations`` (at temperature 1) or when F
    improves by less than ``tol`` (relative).

    Hidden states that look alike are exchangeable under a flat prior, so EM started at the
    prior stays in the symmetric solution; ``init_counts > 0`` starts the posterior at the prior
    plus random counts (exponential, mean ``init_counts``, seeded by ``seed``) to break it.

    EM on an aliased room ends in local optima (a learned state standing for two places with
    the same view, another for none). Two standard remedies, both optional:

    - ``restarts``: that many seeded random starts, run together; the model keeps the one with
      the lowest final free energy (F is the negative ELBO, the model-selection criterion).
    - ``anneal_iterations``: deterministic annealing in its variational-Bayes form (Ueda &
      Nakano 1998 for EM; Katahira, Watanabe & Okada 2008 for VB): the first iterations minimise
      the free energy with the entropy weighted by ``1 / beta``, ``beta`` rising geometrically
      from ``anneal_from`` to 1. Smoothing then uses the tempered joint ``exp(beta E[log p(o,
      s)])`` and the counts become ``beta (prior + expected counts - 1) + 1``, flatter than the
      data alone make them, so the state posterior stays broad and unseen moves stay possible
      (a small prior concentration otherwise rules them out after the first iteration) until the
      data have shaped the transitions. F is the variational free energy only at ``beta = 1``: it is
      reported, and never increases, from the first untempered iteration on."""
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
    if restarts < 1:
        raise ValueError(f"restarts must be >= 1, got {restarts}")
    if anneal_iterations < 0 or not 0.0 < anneal_from <= 1.0:
        raise ValueError(f"anneal_iterations must be >= 0 and anneal_from in (0, 1], "
                         f"got {anneal_iterations}, {anneal_from}")
    n, M = model.num_states[0], len(model.modalities)
    data = _check_sequences(model, sequences)
    R = restarts
    # counts in batch layout: A (R, outcomes, n) per modality, B (R, U, next, prev)
    a0 = [model.live_pA(m)[None].copy() if learn_A else None for m in range(M)]
    b0 = np.moveaxis(model.live_pB(0), 2, 0)[None].copy() if learn_B else None
    rng = np.random.default_rng(seed)
    a = [None if x is None else np.repeat(x, R, axis=0) for x in a0]
    b = None if b0 is None else np.repeat(b0, R, axis=0)
    for r in range(R):  # restart r starts the same whatever the number of restarts
        for x in a:
            if x is not None:
                x[r] += rng.exponential(init_counts, x.shape[1:])
        if b is not None:  # drawn in the model's (next, prev, control) layout
            b[r] += np.moveaxis(rng.exponential(init_counts, model.live_pB(0).shape), 2, 0)
    fixed_logA = [None if learn_A else floor_log(model.live_A(m), TINY_FLOOR) for m in range(M)]
    fixed_B = None if learn_B else np.moveaxis(model.live_B(0), 2, 0)[None]
    d0 = model.live_D(0)
    histories: list[list[float]] = [[] for _ in range(R)]
    steps = np.zeros(R, dtype=int)
    active = np.arange(R)
    for k in range(anneal_iterations + iterations):
        beta = anneal_from ** (1.0 - k / anneal_iterations) if k < anneal_iterations else 1.0
        r = active
        logA = [_elog(a[m][r], axis=1) if learn_A else fixed_logA[m][None] for m in range(M)]
        trans = np.exp(_elog(b[r], axis=2)) if learn_B else fixed_B
        trans = np.broadcast_to(trans ** beta if beta < 1.0 else trans, (r.size,) + trans.shape[1:])
        d = np.broadcast_to(d0 ** beta, (r.size, n))
        F = np.zeros(r.size)
        new_a = [None if x is None else np.repeat(x, r.size, axis=0) for x in a0]
        new_b = None if b0 is None else np.repeat(b0, r.size, axis=0)
        for obs, acts in data:
            lik = np.exp(beta * sum(logA[m][:, obs[:, m]] for m in range(M)))
            lik = np.broadcast_to(lik, (r.size,) + lik.shape[1:])
            with threadpool_limits(1, user_api="blas"):  # small products: threads only add overhead
                gamma, xi, log_z = _forward_backward_batch(lik, trans, acts, d)
            F -= log_z
            if learn_A:  # a[o, s] += sum_t [o_t = o] q(s_t)
                for m in range(M):
                    new_a[m] += np.matmul(np.eye(model.num_obs[m])[:, obs[:, m]], gamma)
            if learn_B:
                new_b += xi
        steps[r] += 1
        if learn_A:
            F += sum(_kl_dirichlet(a[m][r], a0[m]) for m in range(M))
        if learn_B:
            F += _kl_dirichlet(b[r], b0)
        for m in range(M):
            if learn_A:
                a[m][r] = _temper(new_a[m], beta)
        if learn_B:
            b[r] = _temper(new_b, beta)
        if beta < 1.0:
            continue
        still = []
        for j, i in enumerate(r):
            h = histories[i]
            h.append(float(F[j]))
            if not (len(h) > 1 and h[-2] - h[-1] < tol * abs(h[-1])):
                still.append(i)
        active = np.array(still, dtype=int)
        if not active.size:
            break
    final = [h[-1] for h in histories]
    best = int(np.argmin(final))
    for m in range(M):  # live views of the dense factors, written in place
        if learn_A:
            model.A[m].counts_dense()[...] = a[m][best]
            model.A[m].to_dense()[...] = a[m][best] / a[m][best].sum(axis=0, keepdims=True)
    if learn_B:
        counts = np.moveaxis(b[best], 0, 2)
        model.B[0].counts_dense(n)[...] = counts
        model.B[0].to_dense(n)[...] = counts / counts.sum(axis=0, keepdims=True)
    return FitResult(histories[best], int(steps[best]), final, histories, best)


def surprise_bits(model, observations, actions) -> float:
    """Mean predictive surprise ``-log2 p(o_t | o_<t, u_<t)`` per step under the model's
    expected parameters (one factor): the exact filter's ``-log p(o_1:T)`` over ``T ln 2``."""
    actions = [(int(a),) for a in np.asarray(actions, dtype=np.int64).reshape(-1)]
    _, info = bayes_filter(model, [model.live_D(0)], [list(o) for o in observations], actions)
    return info.total_free_energy / (len(observations) * np.log(2.0))

"""The variational free energy of a whole window under any scheme's posterior marginals.

For marginals ``q_t^f`` (time ``t``, factor ``f``), read as the mean-field posterior
``q(s_1:T) = prod_t prod_f q_t^f(s_t^f)``::

    F[q] = sum_t sum_f E[log q_t^f] - sum_f E[log D_f(s_1^f)] - sum_t>1 sum_f E[log B_f(s_t^f | s_t-1^f, u_t-1)]
           - sum_t sum_m E[log A_m(o_t^m | s_t)]

A factor whose next state depends on several factors (``model.B_deps[f]``) contributes
``E[log B_f(s_t^f | s_t-1^deps_f, u_t-1)]`` under the product of the marginals of ``s_t^f`` and of
its dependencies at ``t - 1``.

Gibbs' inequality makes it an upper bound on ``-log p(o_1:T)`` for any marginals, with
equality only for the exact posterior when it factorises; so free energies of different schemes
on the same data are comparable, and none can fall below exact Bayes' ``-log p(o_1:T)``.
Logarithms are floored at machine epsilon, as in the schemes themselves.
"""

from __future__ import annotations

import numpy as np

from .base import dense_transition, expected_loglik, floor_log, prepare, xlogx_sum


def free_energy_terms(model, prob, prior, marginals, start: int = 0) -> np.ndarray:
    """Per-step terms of ``F[q]`` for the steps ``start..T-1`` of the checked problem ``prob``,
    with ``prior[f]`` the belief at ``start`` and ``marginals[k][f]`` the marginal of step
    ``start + k``: entropy, transition (prior at the first step) and likelihood terms of the step."""
    T = prob.T - start
    terms = np.zeros(T)
    deps = getattr(model, "B_deps", None)
    for k in range(T):
        q_k = [np.asarray(q, dtype=float) for q in marginals[k]]
        fe = 0.0
        for f in range(prob.num_factors):
            fe += xlogx_sum(q_k[f])
            if k == 0:
                fe -= float(q_k[f] @ floor_log(prior[f]))
            elif deps is not None and deps[f] != (f,):  # E[log B_f(s^f | s_prev^deps)], product of marginals
                logB = floor_log(model.B[f].prob[..., prob.actions[start + k - 1][f]])
                q_prev = [np.asarray(marginals[k - 1][d], dtype=float) for d in deps[f]]
                fe -= expected_loglik(logB, tuple(range(len(deps[f]) + 1)), [q_k[f], *q_prev])
            else:
                logB = floor_log(dense_transition(model, f, prob.actions[start + k - 1][f]))
                fe -= float(q_k[f] @ logB @ np.asarray(marginals[k - 1][f], dtype=float))
        for ev in prob.evidence[start + k]:
            fe -= expected_loglik(floor_log(ev.lik), ev.deps, q_k) + ev.log_scale
        terms[k] = fe
    return terms


def window_free_energy(model, prior, observations, actions, marginals) -> float:
    """Mean-field variational free energy ``F[q]`` of a whole window under given marginals.

    Comparable across schemes: an upper bound on ``-log p(o_1:T)`` for any marginals (see the module
    docstring for the formula).

    Parameters
    ----------
    model, prior, observations, actions
        The arguments every scheme takes (:class:`cogmap.genmodel.contracts.InferenceScheme`), checked
        and documented by :func:`cogmap.inference.base.prepare`.
    marginals : sequence
        ``T`` entries, each a sequence of ``(num_states[f],)`` float marginals per factor.

    Returns
    -------
    float
        ``F[q]`` in nats.

    Raises
    ------
    ValueError
        If ``marginals`` does not cover the ``T`` steps of ``observations`` (or the inputs are invalid,
        :class:`InferenceError`).
    """
    prob = prepare(model, prior, observations, actions)
    if len(marginals) != prob.T:
        raise ValueError(f"marginals cover {len(marginals)} steps, the observations {prob.T}")
    return float(free_energy_terms(model, prob, prob.prior, marginals).sum())

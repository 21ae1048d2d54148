"""Fixed-point iteration: mean-field posterior over factors, one step at a time.

The update schedule is that of pymdp 1.0 (``run_factorized_fpi``): start from uniform
beliefs, then ``num_iter`` simultaneous sweeps ``q_f <- softmax(log prior_f +
sum_m E_{q(other factors of m)}[log L_m])``; a single-factor model takes one exact pass. A
sweep that leaves every belief bitwise unchanged ends the schedule (the remaining sweeps would
repeat it exactly, so the result is that of all ``num_iter``).
Logarithms use pymdp's floor (machine epsilon). Across time the prior of step ``t`` is the
per-factor prediction of the posterior of step ``t - 1``; ``info.history`` holds the
filtered beliefs.
"""

from __future__ import annotations

import numpy as np

from .base import (
    InferenceInfo,
    check_num_iter,
    check_possible,
    expected_loglik,
    floor_log,
    marginal_loglik,
    predict_factorised,
    prepare,
    softmax,
    xlogx_sum,
)


def mean_field_free_energy(qs, log_prior, logliks) -> float:
    """``sum_f KL-like terms - E_q[log L]`` for a factorised ``q`` (one time step)."""
    fe = 0.0
    for q, lp in zip(qs, log_prior, strict=True):
        fe += xlogx_sum(q) - float(q @ lp)
    for deps, ll, scale in logliks:
        fe -= expected_loglik(ll, deps, qs) + scale
    return fe


def fpi_step(prior, evidence, num_iter: int = 16, tol: float | None = None):
    """One time step of fixed-point iteration; returns ``(qs, free_energy, iterations)``."""
    log_prior = [floor_log(p) for p in prior]
    logliks = [(ev.deps, floor_log(ev.lik), ev.log_scale) for ev in evidence]
    F = len(prior)
    if F == 1:
        log_q = log_prior[0].copy()
        for _deps, ll, _ in logliks:
            log_q = log_q + ll
        qs = [softmax(log_q)]
        return qs, mean_field_free_energy(qs, log_prior, logliks), 1
    # modalities with the same factors are summed once; those of one factor are constant per sweep
    groups: dict = {}
    for deps, ll, _ in logliks:
        groups[deps] = groups[deps] + ll if deps in groups else ll
    const = [lp.copy() for lp in log_prior]
    for deps, ll in groups.items():
        if len(deps) == 1:
            const[deps[0]] += ll
    multi = [[(deps, ll) for deps, ll in groups.items() if len(deps) > 1 and f in deps] for f in range(F)]
    qs = [np.full(p.shape[0], 1.0 / p.shape[0]) for p in prior]
    it = 0
    while it < num_iter:
        it += 1
        new = []
        for f in range(F):
            log_q = const[f]
            for deps, ll in multi[f]:
                log_q = log_q + marginal_loglik(ll, deps, qs, f)
            new.append(softmax(log_q))
        # a sweep that leaves every belief bitwise unchanged is a fixed point: the remaining sweeps
        # of the schedule would repeat it exactly, so stopping changes nothing
        if all(np.array_equal(a, b) for a, b in zip(new, qs, strict=True)) or (
                tol is not None and max(float(np.abs(a - b).max()) for a, b in zip(new, qs, strict=True)) < tol):
            qs = new
            break
        qs = new
    return qs, mean_field_free_energy(qs, log_prior, logliks), it


def fpi(model, prior, observations, actions=None, *, num_iter: int = 16, tol: float | None = None):
    """Mean-field fixed-point iteration, filtered over time (pymdp 1.0's ``fpi``).

    Each step's prior is the previous posterior predicted through ``B``; ``num_iter`` sweeps update
    each factor's belief given the others.

    Parameters
    ----------
    model, prior, observations, actions
        As for :func:`cogmap.inference.exact.exact`.
    num_iter : int, optional
        Sweeps per step, an integer >= 1 (pymdp's default 16).
    tol : float, optional
        Stop early when no belief moves by more than ``tol`` (off by default, to keep pymdp's
        schedule exactly).

    Returns
    -------
    posterior : list of numpy.ndarray
        ``(num_states[f],)`` float belief per factor at the last step, each summing to 1.
    info : InferenceInfo
        ``free_energy`` is the mean-field free energy of the last step, ``total_free_energy`` the
        sum over steps, ``history`` the filtered beliefs, ``iterations`` the sweeps of the last step.

    Raises
    ------
    InferenceError
        If ``num_iter`` is not an integer >= 1, the inputs are invalid, or the observations have
        zero probability under the model (:func:`~cogmap.inference.base.check_possible`).
    """
    num_iter = check_num_iter(num_iter, "fpi")
    prob = prepare(model, prior, observations, actions)
    check_possible(model, prob, "fpi")
    qs = list(prob.prior)
    history = []
    total = 0.0
    fe, it = 0.0, 0
    for t in range(prob.T):
        pri = qs if t == 0 else predict_factorised(model, qs, prob.actions[t - 1])
        qs, fe, it = fpi_step(pri, prob.evidence[t], num_iter, tol)
        total += fe
        history.append(tuple(qs))
    return list(qs), InferenceInfo(fe, tuple(history), it, total)

"""Variational message passing (``vmp``): coordinate ascent on the mean-field free energy of a window.

The posterior over the window is read as ``q(s_1:T) = prod_t prod_f q_t^f(s_t^f)`` and its free
energy ``F[q]`` is that of :mod:`cogmap.inference.free_energy` (logarithms floored at machine
epsilon, as there). Each update replaces one marginal by the exact minimiser of ``F`` over it with
every other marginal held at its current value::

    q_t^f <- softmax( sum_m E_{q_t(other factors of m)}[log A_m(o_t^m | s_t)]
                      + [t = 0: log D_f ; else log B_{t-1}^f q_{t-1}^f]
                      + [t < T-1: q_{t+1}^f log B_t^f] )

with ``log B_t^f[s', s] = log B_f(s' | s, u_t)``. One sweep updates ``t = 0..T-1`` and, within a
step, ``f = 0..F-1`` in order, each update using the neighbours already updated in the sweep
(Gauss-Seidel). Every update lowers ``F`` or leaves it unchanged, so the free energy after each
sweep never increases and converges to a local minimum of the mean-field free energy; as any
mean-field free energy it stays an upper bound on ``-log p(o_1:T)``. Beliefs start uniform.

This is the mean-field VMP of the variational message passing literature. pymdp 1.0's
``run_vmp`` updates every belief at once from the previous sweep's neighbours instead, which is
not a descent on ``F`` and can oscillate far from its minimum; that schedule is the scheme
``vmp_pymdp`` of :mod:`cogmap.inference.message_passing`.

Options: ``num_iter`` (16 sweeps), ``window`` (``None``: the whole sequence; with a shorter
window the steps before it are filtered by fixed-point iteration and the predicted belief is the
window's prior, as for ``vmp_pymdp`` and ``mmp``) and ``tol`` (stop after the first sweep in which
no belief moves by more than ``tol``). There is no step size: each update is the exact
coordinate step.
"""

from __future__ import annotations

import numpy as np

from .base import (
    InferenceError,
    InferenceInfo,
    b_deps_of,
    backward_message,
    check_num_iter,
    check_possible,
    floor_log,
    forward_message,
    marginal_loglik,
    prepare,
    softmax,
    transition_array,
)
from .free_energy import free_energy_terms
from .message_passing import check_window, filter_before_window


def check_tol(tol, scheme: str) -> float | None:
    """``tol`` must be None (run every sweep) or a finite positive number."""
    if tol is None:
        return None
    if isinstance(tol, bool | np.bool_) or not isinstance(tol, int | float | np.integer | np.floating) \
            or not np.isfinite(tol) or tol <= 0:
        raise InferenceError(f"{scheme}: tol must be a positive number or None, got {tol!r}")
    return float(tol)


def coordinate_sweeps(model, prob, start: int, prior, num_iter: int, tol: float | None = None):
    """Coordinate ascent on the mean-field free energy of the steps ``start..T-1`` of ``prob``.

    Parameters
    ----------
    model : Model
        Compiled model.
    prob : Problem
        Checked inputs (:func:`cogmap.inference.base.prepare`).
    start : int
        First step of the window.
    prior : sequence of numpy.ndarray
        ``(sizes[f],)`` belief per factor at ``start``, before its observation.
    num_iter : int
        Most sweeps to run (>= 1).
    tol : float, optional
        Stop after the first sweep in which no belief moves by more than ``tol``.

    Returns
    -------
    qs : list of list of numpy.ndarray
        ``qs[k][f]``: the marginal of factor ``f`` at step ``start + k``.
    sweeps : int
        Sweeps run.
    """
    T = prob.T - start
    F = prob.num_factors
    # with transitions that depend on several factors (model.B_deps) the transition term of factor g
    # at t is E[log B_g(s_t^g | s_t-1^deps_g)] under the product of marginals; its message to a
    # marginal is its expectation over every other marginal it involves, so each update is still the
    # exact coordinate minimiser of the window's free energy
    deps = b_deps_of(model)
    users = [[g for g in range(F) if f in deps[g]] for f in range(F)]
    logB = [[floor_log(transition_array(model, g, prob.actions[start + t][g])) for g in range(F)]
            for t in range(T - 1)]
    logliks = [[(ev.deps, floor_log(ev.lik)) for ev in prob.evidence[start + t]] for t in range(T)]
    log_prior = [floor_log(p) for p in prior]
    qs = [[np.full(n, 1.0 / n) for n in prob.sizes] for _ in range(T)]
    sweeps = 0
    while sweeps < num_iter:
        sweeps += 1
        moved = 0.0
        for t in range(T):
            for f in range(F):
                x = log_prior[f] if t == 0 else forward_message(logB[t - 1][f], deps[f], f, qs[t - 1])
                if t < T - 1:  # every factor whose transition to t + 1 depends on f
                    for g in users[f]:
                        x = x + backward_message(logB[t][g], deps[g], g, f, qs[t + 1][g], qs[t])
                for mdeps, ll in logliks[t]:
                    if f in mdeps:
                        x = x + marginal_loglik(ll, mdeps, qs[t], f)
                new = softmax(x)
                moved = max(moved, float(np.abs(new - qs[t][f]).max()))
                qs[t][f] = new
        if tol is not None and moved <= tol:
            break
    return qs, sweeps


def vmp(model, prior, observations, actions=None, *, num_iter: int = 16, window: int | None = None,
        tol: float | None = None):
    """Variational message passing: coordinate ascent on the mean-field free energy of a window.

    Each update sets one marginal ``q_t^f`` to the exact minimiser of the window's free energy
    given the current values of all the others, in the order ``t = 0..T-1``, ``f = 0..F-1``
    (see the module docstring), so the free energy never increases from one sweep to the next.

    Parameters
    ----------
    model : Model
        Compiled model (:func:`cogmap.genmodel.compile`).
    prior : list of numpy.ndarray
        One belief per factor at the first step, before its observation: ``(num_states[f],)``
        float, sums to 1.
    observations : sequence
        ``T >= 1`` steps, as for every scheme (:mod:`cogmap.inference.base`).
    actions : sequence, optional
        ``T - 1`` control tuples, one integer per factor.
    num_iter : int, optional
        Sweeps over the window, an integer >= 1 (default 16).
    window : int, optional
        Number of last steps smoothed together (>= 1); the steps before are filtered by
        fixed-point iteration. Default None: the whole sequence.
    tol : float, optional
        Stop after the first sweep in which no belief moves by more than ``tol`` (a positive
        number). Default None: run all ``num_iter`` sweeps.

    Returns
    -------
    posterior : list of numpy.ndarray
        ``(num_states[f],)`` float belief per factor at the last step.
    info : InferenceInfo
        ``total_free_energy`` is the mean-field free energy of the window (an upper bound on
        ``-log p(o_window)``), ``free_energy`` its terms that involve the last step, ``history``
        the smoothed beliefs of the window (filtered ones before it), ``iterations`` the sweeps
        run.

    Raises
    ------
    InferenceError
        If ``num_iter``, ``window`` or ``tol`` is invalid, the inputs are
        (:func:`~cogmap.inference.base.prepare`), or the observations have zero probability under
        the model (:func:`~cogmap.inference.base.check_possible`).
    """
    num_iter = check_num_iter(num_iter, "vmp")
    prob = prepare(model, prior, observations, actions)
    window = check_window(window, "vmp")
    tol = check_tol(tol, "vmp")
    check_possible(model, prob, "vmp")
    start, history, pri = filter_before_window(model, prob, window, num_iter)
    qs, sweeps = coordinate_sweeps(model, prob, start, pri, num_iter, tol)
    terms = free_energy_terms(model, prob, pri, qs, start)
    history.extend(tuple(q) for q in qs)
    return list(qs[-1]), InferenceInfo(float(terms[-1]), tuple(history), sweeps, float(terms.sum()))

"""Window message passing with simultaneous updates, as pymdp 1.0 (``vmp_pymdp``, ``mmp``).

Beliefs ``q_t^f`` for every step of the window and every factor start uniform and are updated
all at once, ``num_iter`` times, following pymdp 1.0 (``run_vmp`` / ``run_mmp``):

``log q_t^f <- log q_t^f + tau * (E[log L_t] - log q_t^f + m_past + m_future)``

* ``vmp_pymdp``: ``m_future = sum_s' log B[s, s'] q_{t-1}(s')`` (``log D`` at the window start)
  and ``m_past = sum_s' q_{t+1}(s') log B[s', s]``. These are the messages of variational
  message passing, but updating every belief at once from the previous sweep's neighbours is
  not a descent on the free energy: it can oscillate and stay far from the mean-field optimum.
  It is kept for agreement with pymdp; :mod:`cogmap.inference.mean_field` has ``vmp``, which
  minimises the same free energy one belief at a time.
* ``mmp``: ``m_future = 1/2 log(B q_{t-1})`` and ``m_past = 1/2 log(q_{t+1} . B~)`` with ``B~``
  the transition normalised over the current state; messages at the window's last step carry
  full weight.

Options: ``num_iter`` (16), ``tau`` (1.0) and ``window`` (``None``: the whole sequence). With
a window shorter than the sequence, the steps before it are filtered by fixed-point iteration
and the predicted belief becomes the window's prior (:func:`filter_before_window`).
``info.history`` holds the smoothed beliefs of the window (filtered ones before it).
``info.total_free_energy`` is the mean-field free energy of the window (an upper bound on
``-log p(o_window)``); ``info.free_energy`` holds the terms of it that involve the last step.
"""

from __future__ import annotations

import numpy as np

from .base import (
    LOG_FLOOR,
    InferenceError,
    InferenceInfo,
    b_deps_of,
    backward_message,
    check_num_iter,
    check_possible,
    floor_log,
    forward_message,
    marginal_loglik,
    predict_factorised,
    prepare,
    softmax,
    transition_array,
)
from .fpi import fpi_step
from .free_energy import free_energy_terms


def _run(model, prob, start: int, prior, kind: str, num_iter: int, tau: float):
    """pymdp 1.0's simultaneous updates (``vmp_pymdp``) or marginal message passing (``mmp``) over
    the steps ``start..T-1``. With transitions that depend on several factors (``model.B_deps``)
    the forward message of ``q_t^f`` contracts ``B_f`` (``log B_f`` for vmp) with the dependencies'
    beliefs at ``t - 1``; the backward one sums, over every factor ``g`` whose transition depends on
    ``f``, the message from ``q_t+1^g`` through ``B_g`` contracted with the beliefs at ``t`` of
    ``g``'s other dependencies."""
    T = prob.T - start
    F = prob.num_factors
    sizes = prob.sizes
    deps = b_deps_of(model)
    users = [[g for g in range(F) if f in deps[g]] for f in range(F)]
    B = [[transition_array(model, g, prob.actions[start + t][g]) for g in range(F)] for t in range(T - 1)]
    logB = [[floor_log(b) for b in step] for step in B]
    if kind == "mmp":  # backward matrices of factors that depend on themselves alone, once
        Bn = [[_normalised_columns(b, deps[g], g, None) if deps[g] == (g,) else None for g, b in enumerate(step)]
              for step in B]
    logliks = [[(ev.deps, floor_log(ev.lik)) for ev in prob.evidence[start + t]] for t in range(T)]
    log_prior = [floor_log(p) for p in prior]
    qs = [[np.full(n, 1.0 / n) for n in sizes] for _ in range(T)]
    for _ in range(num_iter):
        new = []
        for t in range(T):
            row = []
            for f in range(F):
                ln_q = floor_log(qs[t][f])
                ln_a = np.zeros(sizes[f])
                for mdeps, ll in logliks[t]:
                    if f in mdeps:
                        ln_a = ln_a + marginal_loglik(ll, mdeps, qs[t], f)
                after = () if t == T - 1 else users[f]
                if kind == "vmp_pymdp":
                    fwd = log_prior[f] if t == 0 else forward_message(logB[t - 1][f], deps[f], f, qs[t - 1])
                    bwd = 0.0
                    for g in after:
                        bwd = bwd + backward_message(logB[t][g], deps[g], g, f, qs[t + 1][g], qs[t])
                else:
                    fwd = log_prior[f] if t == 0 else floor_log(forward_message(B[t - 1][f], deps[f], f, qs[t - 1]))
                    if t < T - 1:
                        fwd = 0.5 * fwd
                    bwd = 0.0
                    for g in after:
                        bn = Bn[t][g] if Bn[t][g] is not None else _normalised_columns(B[t][g], deps[g], f, qs[t])
                        bwd = bwd + 0.5 * floor_log(qs[t + 1][g] @ bn)
                ln_q = ln_q + tau * (ln_a - ln_q + bwd + fwd)
                row.append(softmax(ln_q))
            new.append(row)
        qs = new
    # mean-field free energy of the window, split so the last step's terms can be reported
    return qs, free_energy_terms(model, prob, prior, qs, start)


def _normalised_columns(b: np.ndarray, deps_g: tuple[int, ...], f: int, q_now) -> np.ndarray:
    """mmp's backward matrix: ``B_g`` with ``g``'s dependencies other than ``f`` contracted with
    their beliefs ``q_now``, as ``(next of g, state of f)``, each row normalised over ``s^f``."""
    k = deps_g.index(f)
    x = b
    for j in range(len(deps_g) - 1, -1, -1):
        if j != k:
            x = np.moveaxis(x, 1 + j, -1) @ q_now[deps_g[j]]
    return x / np.maximum(x.sum(axis=1, keepdims=True), LOG_FLOOR)


def check_window(window, scheme: str) -> int | None:
    """``window`` must be None (the whole sequence) or an integer >= 1."""
    if window is None:
        return None
    if isinstance(window, bool | np.bool_) or not isinstance(window, int | np.integer):
        raise InferenceError(f"{scheme}: window must be an integer >= 1 or None, got {window!r}")
    if window < 1:
        raise InferenceError(f"{scheme}: window must be >= 1, got {window}")
    return int(window)


def filter_before_window(model, prob, window: int | None, num_iter: int):
    """Filter the steps before the last ``window`` ones by fixed-point iteration.

    Returns ``(start, history, prior)``: the first step of the window, the filtered beliefs of
    the steps before it and the belief predicted for ``start`` (``prob.prior`` when the window
    covers the whole sequence).
    """
    start = 0 if window is None else max(0, prob.T - window)
    history = []
    pri = list(prob.prior)
    for t in range(start):
        qs_t, _, _ = fpi_step(pri, prob.evidence[t], num_iter)
        history.append(tuple(qs_t))
        pri = predict_factorised(model, qs_t, prob.actions[t])
    return start, history, pri


_TITLES = {
    "vmp_pymdp": "Variational message passing with pymdp 1.0's simultaneous updates (``run_vmp``)",
    "mmp": "Marginal message passing with pymdp 1.0's simultaneous updates (``run_mmp``)",
}


def _window_scheme(kind: str):
    def scheme(model, prior, observations, actions=None, *, num_iter: int = 16, tau: float = 1.0,
               window: int | None = None):
        num_iter = check_num_iter(num_iter, kind)
        prob = prepare(model, prior, observations, actions)
        window = check_window(window, kind)
        check_possible(model, prob, kind)
        start, history, pri = filter_before_window(model, prob, window, num_iter)
        qs, terms = _run(model, prob, start, pri, kind, num_iter, tau)
        history.extend(tuple(q) for q in qs)
        info = InferenceInfo(float(terms[-1]), tuple(history), num_iter, float(terms.sum()))
        return list(qs[-1]), info

    scheme.__name__ = kind
    scheme.__qualname__ = kind
    scheme.__doc__ = f"""{_TITLES[kind]} over a window of time steps (see the module docstring).

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
        Simultaneous update sweeps, an integer >= 1 (default 16, as pymdp 1.0).
    tau : float, optional
        Step size of each update, default 1.
    window : int, optional
        Number of last steps smoothed together (>= 1); the steps before are filtered by
        fixed-point iteration. Default None: the whole sequence.

    Returns
    -------
    posterior : list of numpy.ndarray
        ``(num_states[f],)`` float belief per factor at the last step.
    info : InferenceInfo
        ``total_free_energy`` is the mean-field free energy of the window, ``free_energy`` its
        terms that involve the last step, ``history`` the smoothed beliefs of the window
        (filtered ones before it), ``iterations`` ``num_iter``.

    Raises
    ------
    InferenceError
        If ``num_iter`` or ``window`` is invalid, the inputs are (:func:`prepare`), the
        observations have zero probability under the model
        (:func:`~cogmap.inference.base.check_possible`).
    """
    return scheme


vmp_pymdp = _window_scheme("vmp_pymdp")
mmp = _window_scheme("mmp")

"""AIMAPP's single-factor Bayes filter over a (possibly sparse, growing) topological map.

Each step predicts through ``B`` (dense, or sparse successor lists at O(states x slots)),
multiplies by the likelihood of every reported modality and, when the observation carries a
metric pose, by the pose kernel ``exp(-|p - poses[s]|^2 / (2 sigma^2))`` over live states, then
normalises. Everything works on the live slice, so not-yet-live states get exactly zero mass.
This is exact Bayes for one factor; ``info.history`` holds the filtered beliefs.
"""

from __future__ import annotations

import numpy as np

from .base import InferenceError, InferenceInfo, prepare


def _log_space_update(prior, evidence, t):
    with np.errstate(divide="ignore"):
        logq = np.log(prior)
        for ev in evidence:
            logq = logq + np.log(ev.lik)
    top = logq.max()
    if not np.isfinite(top):
        raise InferenceError(f"filter: observations up to step {t} have zero probability under the model")
    q = np.exp(logq - top)
    c = q.sum()
    return q / c, float(top + np.log(c))


def bayes_filter(model, prior, observations, actions=None):
    """AIMAPP's single-factor forward Bayes filter (exact Bayes for one factor).

    Each step predicts through ``B``, multiplies by the likelihood of every reported modality (and
    the pose kernel) and normalises; an underflowing product is redone in log space.

    Parameters
    ----------
    model, prior, observations, actions
        The arguments every scheme takes (:class:`cogmap.genmodel.contracts.InferenceScheme`), checked
        and documented by :func:`cogmap.inference.base.prepare`.

    Returns
    -------
    posterior : list of numpy.ndarray
        ``(num_states[f],)`` float belief per factor at the last step, each summing to 1.
    info : InferenceInfo
        ``free_energy`` is ``-log p(o_T | o_<T)``, ``total_free_energy`` ``-log p(o_1:T)``,
        ``history`` the filtered beliefs, ``iterations`` 1.

    Raises
    ------
    InferenceError
        If the model has more than one factor, the inputs are invalid (:func:`prepare`), or the
        observations have zero probability under the model.
    """
    if len(model.factors) != 1:
        raise InferenceError(
            f"filter: handles single-factor models only (this one has {len(model.factors)} "
            "factors); use 'exact', 'fpi', 'vmp' or 'mmp'"
        )
    prob = prepare(model, prior, observations, actions)
    q = prob.prior[0]
    history = []
    total = 0.0
    fe = 0.0
    for t in range(prob.T):
        if t > 0:
            q = model.predict(0, q, prob.actions[t - 1][0])
        prior_t = q
        scale = 0.0
        for ev in prob.evidence[t]:
            q = q * ev.lik
            scale += ev.log_scale
        c = q.sum()
        if c > 0 and np.isfinite(c):
            q = q / c
            log_c = float(np.log(c))
        else:  # the product underflowed: redo it in log space
            q, log_c = _log_space_update(prior_t, prob.evidence[t], t)
        fe = -(log_c + scale)
        total += fe
        history.append((q,))
    return [q], InferenceInfo(fe, tuple(history), 1, total)

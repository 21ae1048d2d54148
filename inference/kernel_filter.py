"""Gaussian-kernel belief update over binned factors (the drone's ``"kernel"`` scheme).

DRONE.md 2.4 (e98ed45 ``Inference.jl``): for each factor with observed value o,
L_i = exp(-1/2 ((bin_i - o) / w)^2) (wrapped difference for azimuth), L /= sum L,
b = (1 - rate) b + rate L (rate 0.2), renormalise; the distance factor is then reweighted by
1 + exp(-d/10) (125 - bin)/125 and renormalised.

Call convention (as every scheme, :mod:`cogmap.inference.base`)::

    posterior, info = kernel_filter(model, prior, observations)

``model`` is a :class:`~cogmap.genmodel.drone_beliefs.KernelBeliefModel`; ``observations`` a
sequence over time of dicts ``{factor name: value}`` (absent factors are not updated). ``prior`` is
one belief per factor, or ``None`` for the published *per-call re-initialisation*: start uniform and
apply ``initialize_beliefs``' update with the first observation before the regular updates, so one
call with one observation gives 0.64 u + 0.36 L. Passing the previous posterior as ``prior`` gives
persistent beliefs (one observation: 0.8 b + 0.2 L). The likelihood is computed in log space and
shifted by its maximum before normalising, which equals the formula whenever it does not underflow
(and picks the nearest bin when it would, e.g. a distance beyond 125 m).
``info.free_energy`` is -sum_f log sum_i b_i L_i with the unnormalised kernel L: the surprise of the
last observation under the predicted beliefs, up to the kernels' constants.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from cogmap.genmodel.drone_beliefs import MAX_DISTANCE, KernelBeliefModel, kernel_width

from .base import InferenceError, InferenceInfo


def kernel_likelihood(factor, obs: float, width: float) -> tuple[np.ndarray, float]:
    """Normalised kernel L over the factor's bins and log sum of the unnormalised kernel."""
    z = -0.5 * (factor.difference(obs) / width) ** 2
    m = float(z.max())
    e = np.exp(z - m)
    s = float(e.sum())
    return e / s, m + np.log(s)


def target_weighting(bins: np.ndarray, d: float, max_distance: float = MAX_DISTANCE) -> np.ndarray:
    """Multiplier 1 + exp(-d/10) (max_distance - bin) / max_distance of the distance factor."""
    return 1.0 + np.exp(-float(d) / 10.0) * (max_distance - bins) / max_distance


def update_factor(model: KernelBeliefModel, index: int, belief, obs: float) -> tuple[np.ndarray, float]:
    """One kernel update of factor ``index``; returns (new belief, -log sum b L)."""
    f = model.factors[index]
    lik, log_mass = kernel_likelihood(f, obs, kernel_width(f.name, obs, model.width))
    b = np.asarray(belief, float)
    surprise = -(np.log(max(float(b @ lik), 1e-300)) + log_mass)
    new = (1.0 - model.rate) * b + model.rate * lik
    new /= new.sum()
    if f.name == "distance" and model.target_weighting:
        new = new * target_weighting(f.bins, obs)
        new /= new.sum()
    return new, float(surprise)


def _check(model, prior, observations):
    if not isinstance(model, KernelBeliefModel):
        raise InferenceError(f"kernel_filter: model must be a KernelBeliefModel, got {type(model).__name__}")
    if isinstance(observations, Mapping) or not isinstance(observations, Sequence) or len(observations) == 0:
        raise InferenceError("kernel_filter: observations must be a non-empty sequence of {factor: value} dicts")
    names = model.names
    for t, o in enumerate(observations):
        if not isinstance(o, Mapping):
            raise InferenceError(f"kernel_filter: observation {t} must be a dict of factor values")
        bad = [k for k in o if k not in names]
        if bad:
            raise InferenceError(f"kernel_filter: observation {t} names unknown factor(s) {bad} (known: {names})")
        for k, v in o.items():
            if v is not None and not np.isfinite(float(v)):
                raise InferenceError(f"kernel_filter: observation {t}, factor '{k}' is not finite ({v})")
    if prior is None:
        return None
    if len(prior) != len(model.factors):
        raise InferenceError(f"kernel_filter: prior has {len(prior)} factors, the model {len(model.factors)}")
    out = []
    for f, b in zip(model.factors, prior, strict=True):
        b = np.asarray(b, float)
        if b.shape != (f.n,) or (b < 0).any() or abs(b.sum() - 1.0) > 1e-6:
            raise InferenceError(f"kernel_filter: prior of '{f.name}' must be a distribution over {f.n} bins")
        out.append(b)
    return out


def kernel_filter(model: KernelBeliefModel, prior, observations, actions=None, **options):
    """Kernel-belief filtering of the drone's binned factors over continuous observations.

    For each factor with observed value ``o``: ``L_i = exp(-1/2 ((bin_i - o) / w)^2)`` (wrapped for
    azimuth), normalised, then ``b = (1 - rate) b + rate L``; the distance factor is then reweighted
    by :func:`target_weighting` (see the module docstring, DRONE.md 2.4).

    Parameters
    ----------
    model : KernelBeliefModel
        The binned factors, kernel widths and update rate.
    prior : list of numpy.ndarray or None
        ``(n_bins,)`` float belief per factor (each sums to 1), or None for the published per-call
        re-initialisation (uniform plus one update with the first observation).
    observations : sequence of dict
        Non-empty; each ``{factor name: value}`` (metres for distance, radians for angles); absent
        factors are not updated.
    actions : optional
        Accepted for the common signature and ignored (no transition model).
    **options
        Ignored.

    Returns
    -------
    posterior : list of numpy.ndarray
        ``(n_bins,)`` float belief per factor, each summing to 1.
    info : InferenceInfo
        ``free_energy`` is ``-sum_f log sum_i b_i L_i`` of the last observation (unnormalised
        kernels), ``history`` the beliefs after each step.

    Raises
    ------
    InferenceError
        For a model of another type, an empty or malformed observation sequence, unknown factor
        names, non-finite values, or a prior that is not a distribution per factor.
    """
    beliefs = _check(model, prior, observations)
    observations = list(observations)
    if beliefs is None:  # initialize_beliefs: uniform plus one update with the first observation
        beliefs = model.uniform()
        for i, f in enumerate(model.factors):
            v = observations[0].get(f.name)
            if v is not None:
                beliefs[i], _ = update_factor(model, i, beliefs[i], float(v))
    history = []
    fe = 0.0
    for o in observations:
        fe = 0.0
        for i, f in enumerate(model.factors):
            v = o.get(f.name)
            if v is not None:
                beliefs[i], s = update_factor(model, i, beliefs[i], float(v))
                fe += s
        history.append(tuple(b.copy() for b in beliefs))
    return beliefs, InferenceInfo(free_energy=fe, history=tuple(history), iterations=1)

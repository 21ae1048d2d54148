"""Bayesian model reduction for Dirichlet parameters (Friston, Parr and Zeidman 2018).

With posterior counts ``q``, prior ``p`` and a reduced (or expanded) prior ``r`` over the same
parameters, the reduced posterior is ``q + r - p`` and

    F = ln B(q) + ln B(r) - ln B(p) - ln B(q + r - p)                      (Eq. 7)

where ``ln B(a) = sum(gammaln(a)) - gammaln(sum(a))`` per column. ``F`` is the free energy of
the alternative model minus that of the current one (a negative log-evidence difference), so
the alternative is accepted exactly when ``F < 0``. The same function serves map expansion
(``r`` adds a state) and pruning (``r`` removes counts).

Two edge cases are decided explicitly rather than by floating-point luck:

* an exact zero in ``r`` where data was observed (``q - p > 0``) means the alternative gives
  that data probability zero: ``F = +inf`` and the reduction is rejected (the limit of Eq. 7
  as ``r -> 0`` there; the formula itself would silently drop the entry);
* a tie keeps the current model: columns where ``r`` equals ``p`` exactly contribute exactly
  0 (not a rounding residue), and the alternative is accepted only when ``F < 0`` strictly,
  so ``F == 0`` rejects it.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from scipy.special import gammaln

from cogmap.genmodel.spec import SpecError


class Reduction(NamedTuple):
    free_energy: float  # F(alternative) - F(current); accept when negative
    posterior: np.ndarray  # counts of the alternative model's posterior, q + r - p
    accept: bool


def log_beta(a: np.ndarray, axis: int = 0) -> np.ndarray:
    """Log multivariate Beta function of Dirichlet parameters ``a`` along ``axis``.

    Zero entries are treated as absent outcomes (they contribute nothing), so sparse count
    arrays can be compared column by column.
    """
    a = np.asarray(a, dtype=float)
    safe = np.where(a > 0, a, 1.0)
    return np.sum(np.where(a > 0, gammaln(safe), 0.0), axis=axis) - gammaln(np.sum(a, axis=axis))


def reduce_dirichlet(q, p, r, axis: int = 0) -> Reduction:
    """Free-energy change of swapping prior ``p`` for ``r`` given posterior ``q`` (Eq. 7)."""
    q, p, r = (np.asarray(x, dtype=float) for x in (q, p, r))
    if not q.shape == p.shape == r.shape:
        raise SpecError(f"reduce_dirichlet: shapes differ: q {q.shape}, p {p.shape}, r {r.shape}")
    for name, x in (("q", q), ("p", p), ("r", r)):
        if not np.all(np.isfinite(x)) or np.any(x < 0):
            raise SpecError(f"reduce_dirichlet: {name} must be finite and non-negative")
    s = q + r - p
    if np.any(s < -1e-12):
        raise SpecError("reduce_dirichlet: q + r - p has negative counts (r removes more than was learned)")
    s = np.maximum(s, 0.0)
    if np.any((r == 0) & (q - p > 0)):  # the alternative cannot explain observed data
        return Reduction(float("inf"), s, False)
    F = log_beta(q, axis) + log_beta(r, axis) - log_beta(p, axis) - log_beta(s, axis)
    F = np.where(np.all(r == p, axis=axis), 0.0, F)  # an unchanged column is an exact tie
    total = float(np.sum(F))
    return Reduction(total, s, total < 0)  # strict: a tie keeps the current model


def log_evidence(counts, prior, axis: int = 0) -> float:
    """ln p(data | prior) of categorical data with sufficient ``counts`` under a Dirichlet prior
    (the Dirichlet-multinomial marginal likelihood of one ordered sequence)."""
    counts, prior = np.asarray(counts, dtype=float), np.asarray(prior, dtype=float)
    return float(np.sum(log_beta(prior + counts, axis) - log_beta(prior, axis)))

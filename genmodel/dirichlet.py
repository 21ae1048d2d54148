"""Dirichlet counts of a likelihood: the update of Eq. (8) and the expected parameters."""

from __future__ import annotations

import numpy as np
from scipy.special import digamma

from .numerics import LOG_FLOOR, normalise
from .spec import SpecError


def novelty(a: np.ndarray, a0: np.ndarray) -> np.ndarray:
    """Parameter information-gain weight of Dirichlet entries ``a`` in columns of total ``a0``:
    ``W = ln a0 - ln a + psi(a + 1) - psi(a0 + 1)`` (Da Costa et al. 2020, D.15), both floored
    at the log floor."""
    a = np.maximum(a, LOG_FLOOR)
    a0 = np.maximum(a0, LOG_FLOOR)
    return np.log(a0) - np.log(a) + digamma(a + 1.0) - digamma(a0 + 1.0)


def update_pA(pA: np.ndarray, obs, qs: list[np.ndarray], lr: float = 1.0, floor: float = 1e-3) -> np.ndarray:
    """``pA + lr * o (x) q(s_deps)`` for one modality; ``obs`` is an index or a distribution."""
    pA = np.asarray(pA, dtype=float)
    o = as_distribution(obs, pA.shape[0])
    outer = o
    for q in qs:
        outer = np.multiply.outer(outer, np.asarray(q, dtype=float))
    if outer.shape != pA.shape:
        raise SpecError(f"update_pA: outer product shape {outer.shape} does not match pA {pA.shape}")
    new = pA + lr * outer
    return np.where(outer > 0, np.maximum(new, floor), new)


def normalise_counts(p: np.ndarray) -> np.ndarray:
    """Expected parameters of Dirichlet counts (columns over the first axis)."""
    return normalise(p, axis=0)


def as_distribution(obs, n: int) -> np.ndarray:
    if np.ndim(obs) == 0:
        o = int(obs)
        if not 0 <= o < n:
            raise SpecError(f"observation {o} out of range [0, {n})")
        v = np.zeros(n)
        v[o] = 1.0
        return v
    v = np.asarray(obs, dtype=float)
    if v.shape != (n,):
        raise SpecError(f"observation distribution has shape {v.shape}, expected ({n},)")
    return v

"""Convergence diagnostics of MCMC draws: split R-hat and effective sample size (numpy).

Both follow Gelman et al., *Bayesian Data Analysis* (3rd ed., section 11.4-11.5) as Stan computes
them: chains are split in halves; R-hat compares the between-half and within-half variances;
the effective sample size sums the autocorrelations of the combined chains up to Geyer's
initial monotone sequence (pairs of lags summed, truncated at the first negative pair).
``draws`` is ``(chains, samples)`` or ``(chains, samples, k)`` (one value per parameter).
"""

from __future__ import annotations

import numpy as np


def _split(draws: np.ndarray) -> np.ndarray:
    x = np.asarray(draws, dtype=float)
    if x.ndim not in (2, 3):
        raise ValueError(f"draws must be (chains, samples) or (chains, samples, k), got shape {x.shape}")
    if x.shape[1] < 4:
        raise ValueError(f"need at least 4 samples per chain, got {x.shape[1]}")
    if x.ndim == 2:
        x = x[..., None]
    half = x.shape[1] // 2
    return np.concatenate([x[:, :half], x[:, -half:]], axis=0)  # (2 chains, half, k)


def _variances(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Within-chain variance ``W`` and the pooled estimate ``(n-1)/n W + B/n`` per parameter of split draws."""
    n = x.shape[1]
    B = n * x.mean(axis=1).var(axis=0, ddof=1)
    W = x.var(axis=1, ddof=1).mean(axis=0)
    return W, (n - 1) / n * W + B / n


def split_rhat(draws) -> np.ndarray:
    """Split potential scale reduction factor per parameter (about 1 when the chains agree).

    Parameters
    ----------
    draws : array_like
        ``(chains, samples)`` or ``(chains, samples, k)`` float.

    Returns
    -------
    numpy.ndarray
        ``(k,)`` float (a 0-d array for 2-D draws).
    """
    W, var = _variances(_split(draws))
    out = np.sqrt(np.where(W > 0, var / np.where(W > 0, W, 1.0), 1.0))
    return out[0] if np.ndim(draws) == 2 else out


def effective_sample_size(draws) -> np.ndarray:
    """Effective number of independent draws per parameter (all chains together).

    Parameters
    ----------
    draws : array_like
        ``(chains, samples)`` or ``(chains, samples, k)`` float.

    Returns
    -------
    numpy.ndarray
        ``(k,)`` float (a 0-d array for 2-D draws).
    """
    x = _split(draws)
    m, n, k = x.shape
    Ws, variances = _variances(x)
    out = np.empty(k)
    for j in range(k):
        W, var = Ws[j], variances[j]
        y = x[:, :, j] - x[:, :, j].mean(axis=1, keepdims=True)
        f = np.fft.rfft(y, n=2 * n, axis=1)
        acov = np.fft.irfft(f * np.conj(f), axis=1)[:, :n] / n  # per-chain autocovariance
        if var <= 0:
            out[j] = m * n
            continue
        rho = 1.0 - (W - acov.mean(axis=0)) / var
        rho[0] = 1.0
        pairs = rho[: 2 * ((n - 1) // 2)].reshape(-1, 2).sum(axis=1)
        stop = np.flatnonzero(pairs < 0)
        pairs = pairs[: stop[0]] if stop.size else pairs
        pairs = np.minimum.accumulate(pairs)  # initial monotone sequence
        tau = -1.0 + 2.0 * pairs.sum()
        out[j] = m * n / max(tau, 1.0 / np.log10(m * n))
    return out[0] if np.ndim(draws) == 2 else out


__all__ = ["effective_sample_size", "split_rhat"]

"""The offline particle filter (Appendix B-I): against an exact Kalman filter, jitter and resampling only at
chunk starts, bad input."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from cogmap.inference.chunked_filter import chunked_filter

Q, R = 0.2**2, 0.3**2  # 1-D random walk z' = z + u + N(0, Q), observed as x = z + N(0, R)


def _simulate(T, seed):
    rng = np.random.default_rng(seed)
    us = rng.normal(0, 0.5, T)
    zs = np.cumsum(us + rng.normal(0, np.sqrt(Q), T))
    return us, zs + rng.normal(0, np.sqrt(R), T)


def _kalman(us, xs, m0, p0):
    m, p, means, stds = m0, p0, [], []
    for u, x in zip(us, xs, strict=True):
        m, p = m + u, p + Q
        k = p / (p + R)
        m, p = m + k * (x - m), (1 - k) * p
        means.append(m)
        stds.append(np.sqrt(p))
    return np.array(means), np.array(stds)


def _transition(key, z, u):
    return z + u + np.sqrt(Q) * jax.random.normal(key, z.shape)


def _log_likelihood(z, x):
    return -0.5 * (z[:, 0] - x) ** 2 / R


# chunk 1 is the bootstrap filter. With chunk 5 the weights multiply over up to five steps before a
# resampling, so the effective sample size falls (to 76 of 20,000 at its lowest on this sequence) and the
# Monte Carlo error of the mean grows to about 1 / sqrt(76) = 0.11 Kalman std: hence the wider tolerance.
@pytest.mark.parametrize(("chunk", "tol_mean", "tol_std"), [(1, 0.1, 0.1), (5, 0.25, 0.2)])
def test_matches_kalman_filter(chunk, tol_mean, tol_std):
    us, xs = _simulate(30, 0)
    k_mean, k_std = _kalman(us, xs, 0.0, 0.5**2)
    start = 0.5 * jax.random.normal(jax.random.PRNGKey(3), (20000, 1))
    out = chunked_filter(jax.random.PRNGKey(1), start, jnp.asarray(us), jnp.asarray(xs), _transition,
                         _log_likelihood, chunk=chunk, jitter=0.0)
    assert np.max(np.abs(np.asarray(out.mean[:, 0]) - k_mean) / k_std) < tol_mean
    assert np.allclose(np.asarray(out.std[:, 0]), k_std, rtol=tol_std)
    assert out.kept.shape == (30, 8, 1) and out.ess.shape == (30,)


def test_jitter_is_added_once_per_chunk():
    # a still transition and a flat likelihood: only the jitter moves the particles, once per chunk start,
    # so after step t the variance is jitter^2 * (t // chunk + 1)
    T, chunk, jitter = 12, 5, 0.01
    out = chunked_filter(jax.random.PRNGKey(0), jnp.zeros((20000, 2)), jnp.zeros(T), jnp.zeros(T),
                         lambda k, z, u: z, lambda z, x: jnp.zeros(z.shape[0]), chunk=chunk, jitter=jitter)
    expected = jitter * np.sqrt(np.arange(T) // chunk + 1)
    assert np.allclose(np.asarray(out.std), expected[:, None], rtol=0.03)
    assert np.allclose(np.asarray(out.ess), 20000)


def test_weights_accumulate_inside_a_chunk():
    us, xs = _simulate(20, 1)
    out = chunked_filter(jax.random.PRNGKey(2), jnp.zeros((2000, 1)), jnp.asarray(us), jnp.asarray(xs),
                         _transition, _log_likelihood, chunk=5, jitter=0.0)
    ess = np.asarray(out.ess)
    inside = [t for t in range(20) if t % 5]
    assert all(ess[t] <= ess[t - 1] + 1e-6 for t in inside)  # no resampling between chunk starts
    assert all(ess[t] > ess[t - 1] for t in (5, 10, 15))  # a chunk start resets the weights


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="chunk >= 1"):
        chunked_filter(jax.random.PRNGKey(0), jnp.zeros((4, 1)), jnp.zeros(3), jnp.zeros(3), _transition,
                       _log_likelihood, chunk=0)
    with pytest.raises(ValueError, match="jitter >= 0"):
        chunked_filter(jax.random.PRNGKey(0), jnp.zeros((4, 1)), jnp.zeros(3), jnp.zeros(3), _transition,
                       _log_likelihood, jitter=-1.0)

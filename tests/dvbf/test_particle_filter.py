"""Bootstrap particle filter: against an exact Kalman filter; systematic resampling."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from cogmap import inference
from cogmap.inference.base import InferenceError
from cogmap.inference.particle_filter import pf_init, pf_step, systematic_resample
from cogmap.inference.particle_scheme import ParticleModel

A = np.array([[1.0, 0.1], [0.0, 0.9]])
B = np.array([[0.0], [0.1]])
C = np.array([[1.0, 0.5]])
Q = np.diag([0.05, 0.02]) ** 2 * 25
R = np.array([[0.3**2]])


def _simulate(T, seed):
    rng = np.random.default_rng(seed)
    z = np.zeros(2)
    us = rng.normal(size=(T - 1, 1))
    zs, xs = [], []
    for t in range(T):
        if t:
            z = A @ z + B @ us[t - 1] + rng.multivariate_normal(np.zeros(2), Q)
        zs.append(z)
        xs.append(C @ z + rng.normal(0, np.sqrt(R[0, 0]), 1))
    return np.array(xs), us


def _kalman(xs, us, m0, P0):
    """Exact filtering means, covariances and log p(x_1:T) (numpy reference)."""
    m, P, ll, means, covs = m0, P0, 0.0, [], []
    for t, x in enumerate(xs):
        if t:
            m, P = A @ m + B @ us[t - 1], A @ P @ A.T + Q
        S = C @ P @ C.T + R
        K = P @ C.T @ np.linalg.inv(S)
        r = x - C @ m
        ll += -0.5 * (r @ np.linalg.solve(S, r) + np.linalg.slogdet(2 * np.pi * S)[1])
        m, P = m + K @ r, (np.eye(2) - K @ C) @ P
        means.append(m)
        covs.append(P)
    return np.array(means), np.array(covs), ll


def _linear_model():
    Lq = jnp.asarray(np.linalg.cholesky(Q))

    def transition(key, z, u):
        return z @ A.T + (B @ u) + jax.random.normal(key, z.shape) @ Lq.T

    def log_likelihood(z, x):
        r = (x[0] - z @ C[0]) / np.sqrt(R[0, 0])
        return -0.5 * r * r - 0.5 * np.log(2 * np.pi * R[0, 0])

    return ParticleModel(transition, log_likelihood)


def test_matches_kalman_filter():
    T = 25
    xs, us = _simulate(T, 0)
    m0, P0 = np.zeros(2), np.diag([0.5, 0.5]) ** 2
    k_mean, k_cov, k_ll = _kalman(xs, us, m0, P0)
    pf = inference.get("particle_filter")
    (parts, w), info = pf(_linear_model(), (m0, np.sqrt(np.diag(P0))), xs, us, num_particles=20000, seed=1)
    assert len(info.history) == T
    means = np.array([h[0] for h in info.history])
    stds = np.array([h[1] for h in info.history])
    k_std = np.sqrt(np.diagonal(k_cov, axis1=1, axis2=2))
    assert np.max(np.abs(means - k_mean) / k_std) < 0.1
    assert np.allclose(stds, k_std, rtol=0.08)
    assert -info.total_free_energy == pytest.approx(k_ll, abs=0.15)
    assert w.sum() == pytest.approx(1.0, abs=1e-5)


def test_scheme_rejects_bad_input():
    pf = inference.get("particle_filter")
    assert "particle_filter" in inference.available()
    with pytest.raises(InferenceError, match="ParticleModel"):
        pf(object(), (np.zeros(2), np.ones(2)), np.zeros((3, 1)), np.zeros((2, 1)))
    with pytest.raises(InferenceError, match="T - 1"):
        pf(_linear_model(), (np.zeros(2), np.ones(2)), np.zeros((3, 1)), np.zeros((3, 1)))


def test_systematic_resampling_counts_and_normalised_weights():
    w = jnp.asarray(np.random.default_rng(0).dirichlet(np.ones(50)))
    n = 50
    idx = np.asarray(systematic_resample(jax.random.PRNGKey(3), w))
    counts = np.bincount(idx, minlength=50)
    # systematic resampling gives each particle floor(n w) or ceil(n w) copies
    assert np.all(counts >= np.floor(n * np.asarray(w)) - 1e-9) and np.all(counts <= np.ceil(n * np.asarray(w)) + 1e-9)
    model = _linear_model()
    state = pf_init(jnp.asarray(np.random.default_rng(1).normal(size=(n, 2))), jnp.array([0.3]), model.log_likelihood)
    for t in range(5):
        state, _ = pf_step(jax.random.PRNGKey(t), state, jnp.array([0.5]), jnp.array([0.1 * t]),
                           model.transition, model.log_likelihood)
        assert float(jnp.sum(jnp.exp(state.log_weights))) == pytest.approx(1.0, abs=1e-5)

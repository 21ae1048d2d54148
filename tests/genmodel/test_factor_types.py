"""Dense and sparse factor types answer every shared operation identically."""

from __future__ import annotations

import numpy as np
import pytest

from cogmap.genmodel import DenseLikelihood, DenseTransitions, SparseLikelihood, SparseTransitions


def _pair(seed, n=6, u=3, cap=8):
    rng = np.random.default_rng(seed)
    prob = np.zeros((cap, cap, u))
    for s in range(n):
        for a in range(u):
            succ = rng.choice(n, size=2, replace=False)
            prob[succ, s, a] = rng.dirichlet(np.ones(2))
    prob[np.arange(n, cap), np.arange(n, cap), :] = 1.0
    counts = 4 * prob
    dense = DenseTransitions(prob.copy(), counts.copy())
    sparse = SparseTransitions.from_dense(prob, counts=counts)
    return rng, dense, sparse, n


@pytest.mark.parametrize("seed", range(3))
def test_transition_types_agree_through_learning_and_growth(seed):
    rng, dense, sparse, n = _pair(seed)
    for _ in range(40):
        s, a, t = int(rng.integers(n)), int(rng.integers(3)), int(rng.integers(n))
        lr = float(rng.choice([7.0, -7.0, 5.0, -3.0]))
        dense.learn(s, a, t, lr, n, 1e-3, 10.0)
        sparse.learn(s, a, t, lr, n, 1e-3, 10.0)
    dense.grow(16)
    sparse.grow(16)
    dense.add_state(n, 0.5)
    sparse.add_state(n, 0.5)
    n += 1
    np.testing.assert_allclose(sparse.to_dense(n), dense.to_dense(n), atol=1e-12)
    np.testing.assert_allclose(sparse.counts_dense(n), dense.counts_dense(n), atol=1e-12)
    q = rng.dirichlet(np.ones(n))
    for a in range(3):
        np.testing.assert_allclose(sparse.predict(q, a), dense.predict(q, a), atol=1e-12)
        np.testing.assert_allclose(sparse.column(2, a, n), dense.column(2, a, n), atol=1e-12)
        got = sorted(zip(*(x.tolist() for x in sparse.control_edges(a, n, 0.2)), strict=True))
        want = sorted(zip(*(x.tolist() for x in dense.control_edges(a, n, 0.2)), strict=True))
        assert [(s, t) for s, t, _ in got] == [(s, t) for s, t, _ in want]
        np.testing.assert_allclose([p for *_, p in got], [p for *_, p in want], atol=1e-12)
    assert set(zip(*(x.tolist() for x in sparse.edges(0.3, n)), strict=True)) == set(
        zip(*(x.tolist() for x in dense.edges(0.3, n)), strict=True))


def test_likelihood_types_agree_on_rows_learning_and_statistics():
    rng = np.random.default_rng(0)
    sparse = SparseLikelihood(5, 0, capacity=8)
    for _ in range(6):
        sparse.add_state(0, float(rng.uniform(0.05, 0.3)))
    for _ in range(15):
        q = np.zeros(6)
        q[rng.choice(6, size=2, replace=False)] = [0.7, 0.3]
        sparse.learn(int(rng.integers(5)), [q], 2.0)
    prob = np.zeros((8, 8))
    counts = np.zeros((8, 8))
    prob[:5, :6], counts[:5, :6] = sparse.to_dense(), sparse.counts_dense()
    dense = DenseLikelihood(prob, counts, 5, (6,))
    q = np.zeros(6)
    q[[1, 4]] = [0.5, 0.5]
    sparse.learn(3, [q], 1.5)
    dense.learn(3, [q], 1.5)
    np.testing.assert_allclose(dense.to_dense(), sparse.to_dense(), atol=1e-12)
    for o in range(5):
        np.testing.assert_allclose(dense.row(o), sparse.row(o), atol=1e-12)
        np.testing.assert_allclose(dense.counts_row(o), sparse.counts_row(o), atol=1e-12)
    p = rng.dirichlet(np.ones(5))
    np.testing.assert_allclose(dense.expected_row(p), sparse.expected_row(p), atol=1e-12)
    states = np.array([0, 2, 4])
    np.testing.assert_allclose(dense.column_stats(states)[0], sparse.column_stats(states)[0], atol=1e-12)
    qs = rng.dirichlet(np.ones(3), size=4)
    bg, outcomes, values = sparse.mixture(states, qs)
    full = np.repeat(bg[:, None], 5, axis=1)
    full[:, outcomes] = values
    np.testing.assert_allclose(full, dense.mixture(states, qs)[2], atol=1e-12)
    np.testing.assert_array_equal(dense.taught(1.0), sparse.taught(1.0))
    for s in range(6):
        np.testing.assert_array_equal(dense.outcomes_above(s, 0.3), sparse.outcomes_above(s, 0.3))

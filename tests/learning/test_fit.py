"""Learning A and B from sequences: the smoothing step against brute force, a free energy that
never increases, and a better predictive model than the prior one."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from cogmap.genmodel import Factor, Modality, ModelSpec, SpecError, compile
from cogmap.genmodel.demo_models import aliased_room
from cogmap.inference.fit import _forward_backward, fit, surprise_bits


def _room(side=4, views=6, noise=0.05, learn=False, seed=7):
    A, B, _ = aliased_room(side, views, noise, seed)
    n = side * side
    spec = ModelSpec([Factor("place", n, num_controls=5)], [Modality("view", views, ("place",))],
                     A={"view": A}, B={"place": np.full((n, n, 5), 1 / n) if learn else B},
                     D={"place": np.full(n, 1 / n)})
    if learn:
        spec.pA["view"] = A * 20 + 0.1
        spec.pB["place"] = np.full((n, n, 5), 0.1)
    return compile(spec), A, B


def _walk(A, B, T, seed):
    rng = np.random.default_rng(seed)
    s = int(rng.integers(B.shape[0]))
    obs, acts = [], []
    for t in range(T):
        if t:
            acts.append(int(rng.integers(5)))
            s = int(rng.choice(B.shape[0], p=B[:, s, acts[-1]]))
        obs.append([int(rng.choice(A.shape[0], p=A[:, s]))])
    return obs, acts


def test_smoothing_step_matches_path_enumeration():
    rng = np.random.default_rng(0)
    n, T = 3, 4
    lik = rng.uniform(0.1, 1.0, size=(T, n))
    trans = [rng.dirichlet(np.ones(n), size=n).T for _ in range(2)]
    acts = np.array([0, 1, 1])
    d = rng.dirichlet(np.ones(n))
    gamma, xi, log_z = _forward_backward(lik, trans, acts, d)
    Z, marg, pair = 0.0, np.zeros((T, n)), np.zeros((2, n, n))
    for path in itertools.product(range(n), repeat=T):
        p = d[path[0]] * np.prod([lik[t, path[t]] for t in range(T)])
        p *= np.prod([trans[acts[t - 1]][path[t], path[t - 1]] for t in range(1, T)])
        Z += p
        marg[np.arange(T), path] += p
        for t in range(1, T):
            pair[acts[t - 1], path[t], path[t - 1]] += p
    assert log_z == pytest.approx(np.log(Z), abs=1e-12)
    np.testing.assert_allclose(gamma, marg / Z, atol=1e-12)
    np.testing.assert_allclose(xi, pair / Z, atol=1e-12)


def test_free_energy_never_increases_and_the_learned_model_predicts_better():
    true, A, B = _room()
    train, test = _walk(A, B, 3000, 0), _walk(A, B, 1000, 1)
    model, _, _ = _room(learn=True)
    before = surprise_bits(model, *test)
    res = fit(model, [train], learn_A=True, learn_B=True, iterations=40, init_counts=1.0, seed=0)
    assert res.iterations >= 5
    assert np.all(np.diff(res.free_energy) <= 1e-8 * np.abs(res.free_energy[1:]))
    after = surprise_bits(model, *test)
    assert after < before - 0.5  # bits per step, on held-out data
    assert surprise_bits(true, *test) <= after  # the true model stays the reference
    np.testing.assert_allclose(model.live_B(0).sum(axis=0), 1.0, atol=1e-12)


def test_fit_refuses_what_it_cannot_learn():
    model, A, B = _room()
    obs, acts = _walk(A, B, 10, 0)
    with pytest.raises(SpecError, match="pB"):
        fit(model, [(obs, acts)], learn_A=False, learn_B=True)
    learnable, _, _ = _room(learn=True)
    with pytest.raises(ValueError, match="need 9 actions"):
        fit(learnable, [(obs, acts[:-1])])
    with pytest.raises(ValueError, match="outside"):
        fit(learnable, [(obs, [7] * 9)])
    with pytest.raises(ValueError, match="nothing to learn"):
        fit(learnable, [(obs, acts)], learn_A=False, learn_B=False)

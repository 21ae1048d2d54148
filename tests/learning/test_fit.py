"""Learning A and B from sequences: the smoothing step against brute force, a free energy that
never increases, and a better predictive model than the prior one."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from cogmap.genmodel import Factor, Modality, ModelSpec, SpecError, compile
from cogmap.genmodel.demo_models import aliased_room
from cogmap.inference.fit import _forward_backward, _forward_backward_batch, fit, surprise_bits


def _room(side=4, views=6, noise=0.05, learn=False, seed=7, conc=0.1, learn_A=True):
    A, B, _ = aliased_room(side, views, noise, seed)
    n = side * side
    spec = ModelSpec([Factor("place", n, num_controls=5)], [Modality("view", views, ("place",))],
                     A={"view": A}, B={"place": np.full((n, n, 5), 1 / n) if learn else B},
                     D={"place": np.full(n, 1 / n)})
    if learn:
        if learn_A:
            spec.pA["view"] = A * 20 + 0.1
        spec.pB["place"] = np.full((n, n, 5), conc)
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


def _enumerate_paths(lik, trans, acts, d):
    """log Z, state marginals and pairwise sums per control by summing over every path."""
    T, n = lik.shape
    Z, marg, pair = 0.0, np.zeros((T, n)), np.zeros((len(trans), n, n))
    for path in itertools.product(range(n), repeat=T):
        p = d[path[0]] * np.prod([lik[t, path[t]] for t in range(T)])
        p *= np.prod([trans[acts[t - 1]][path[t], path[t - 1]] for t in range(1, T)])
        Z += p
        marg[np.arange(T), path] += p
        for t in range(1, T):
            pair[acts[t - 1], path[t], path[t - 1]] += p
    return np.log(Z), marg / Z, pair / Z


def test_smoothing_step_matches_path_enumeration():
    rng = np.random.default_rng(0)
    n, T = 3, 4
    lik = rng.uniform(0.1, 1.0, size=(T, n))
    trans = [rng.dirichlet(np.ones(n), size=n).T for _ in range(2)]
    acts = np.array([0, 1, 1])
    d = rng.dirichlet(np.ones(n))
    gamma, xi, log_z = _forward_backward(lik, trans, acts, d)
    ref_log_z, ref_marg, ref_pair = _enumerate_paths(lik, trans, acts, d)
    assert log_z == pytest.approx(ref_log_z, abs=1e-12)
    np.testing.assert_allclose(gamma, ref_marg, atol=1e-12)
    np.testing.assert_allclose(xi, ref_pair, atol=1e-12)


def test_batched_smoothing_matches_path_enumeration_for_every_restart():
    rng = np.random.default_rng(1)
    R, n, T, U = 3, 3, 5, 3
    lik = rng.uniform(0.1, 1.0, size=(R, T, n))
    trans = np.stack([[rng.dirichlet(np.ones(n), size=n).T for _ in range(U)] for _ in range(R)])
    acts = np.array([2, 0, 0, 1])  # control 1 once, one control twice
    d = rng.dirichlet(np.ones(n), size=R)
    gamma, xi, log_z = _forward_backward_batch(lik, trans, acts, d)
    for r in range(R):
        ref_log_z, ref_marg, ref_pair = _enumerate_paths(lik[r], list(trans[r]), acts, d[r])
        assert log_z[r] == pytest.approx(ref_log_z, abs=1e-12)
        np.testing.assert_allclose(gamma[r], ref_marg, atol=1e-12)
        np.testing.assert_allclose(xi[r], ref_pair, atol=1e-12)


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


def test_restarts_run_together_give_what_each_gives_alone():
    """Restart r of a batch is the run of restart r alone: same initial draws, same smoothing."""
    true, A, B = _room(side=3, views=3)
    data = [_walk(A, B, 300, 0), _walk(A, B, 200, 2)]  # two sequences
    kw = dict(learn_A=True, learn_B=True, iterations=15, init_counts=1.0, seed=3, anneal_iterations=4)
    batch, _, _ = _room(side=3, views=3, learn=True)
    res = fit(batch, data, restarts=3, **kw)
    alone, _, _ = _room(side=3, views=3, learn=True)
    first = fit(alone, data, restarts=1, **kw)
    np.testing.assert_allclose(res.histories[0], first.free_energy, rtol=1e-10)
    assert res.best == int(np.argmin(res.restart_free_energy))
    assert res.free_energy == res.histories[res.best]
    assert res.restart_free_energy == [h[-1] for h in res.histories]


def test_restarts_and_annealing_reach_the_true_models_surprise_on_an_aliased_room():
    """A 4 x 4 room with 6 views, only B learned (A given), prior concentration 1 / n per move:
    plain EM stops in a local optimum; annealing with 3 restarts (kept by lowest F) comes within
    10 % of the true model's held-out surprise, each restart with a non-increasing F. (The 5 x 5
    room with 8 views and a 10,000-step walk is measured by bench/fit.py.)"""
    true, A, B = _room()
    n = B.shape[0]
    train, test = _walk(A, B, 5000, 0), _walk(A, B, 2000, 1)
    reference = surprise_bits(true, *test)
    plain, _, _ = _room(learn=True, conc=1 / n, learn_A=False)
    fit(plain, [train], learn_A=False, iterations=20, init_counts=1.0, seed=0)
    assert surprise_bits(plain, *test) > 1.1 * reference
    model, _, _ = _room(learn=True, conc=1 / n, learn_A=False)
    res = fit(model, [train], learn_A=False, iterations=100, init_counts=1.0, seed=0, restarts=3,
              anneal_iterations=20)
    assert len(res.histories) == 3
    for h in res.histories:  # monotone within every restart, from the first untempered iteration
        assert len(h) >= 2
        assert np.all(np.diff(h) <= 1e-8 * np.abs(h[1:]))
    assert res.iterations == 20 + len(res.free_energy)
    learned = surprise_bits(model, *test)
    assert reference <= learned <= 1.1 * reference


def test_fit_refuses_bad_restarts_and_annealing():
    model, A, B = _room(learn=True)
    data = [_walk(A, B, 10, 0)]
    with pytest.raises(ValueError, match="restarts"):
        fit(model, data, restarts=0)
    with pytest.raises(ValueError, match="anneal_from"):
        fit(model, data, anneal_iterations=5, anneal_from=0.0)
    with pytest.raises(ValueError, match="anneal_iterations"):
        fit(model, data, anneal_iterations=-1)


def test_the_room_walk_follows_its_moves_and_the_room_model_learns_b_from_flat_counts():
    from cogmap.genmodel.demo_models import room_model, room_walk

    A, B, label = aliased_room(3, 4, 0.05, 7)
    obs, acts, places = room_walk(A, B, 200, 3)
    assert len(obs) == len(places) == 200 and len(acts) == 199
    for t, u in enumerate(acts):
        assert B[places[t + 1], places[t], u] == 1.0  # every move is the deterministic one
    views = np.array([o[0] for o in obs])
    assert np.mean(views == label[places]) > 0.85  # the place's own view with probability 0.95
    assert room_walk(A, B, 200, 3)[1] == acts  # seeded
    true, learner = room_model(A, B), room_model(A, B, conc=0.5)
    assert np.allclose(true.B[0].to_dense(), B)
    assert np.allclose(learner.B[0].to_dense(), 1 / 9) and np.allclose(learner.B[0].counts_dense(), 0.5)

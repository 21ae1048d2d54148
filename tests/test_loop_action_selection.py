"""Habits, action precision and the two sampling modes of the loop, against pymdp 1.0's Agent."""

from __future__ import annotations

import numpy as np
import pytest

from cogmap import loop
from cogmap.envs.jax_worlds import tmaze_model
from cogmap.planning.action_selection import control_probabilities, select_action
from cogmap.planning.policies import enumerate_policies

MODES = {"policy": "full", "marginal": "marginal"}  # ours -> pymdp's sampling_mode


def _episode(pj, sampling, sample, steps=20, seed=0):
    jax = pytest.importorskip("jax")
    jnp = pytest.importorskip("jax.numpy")
    pytest.importorskip("pymdp")
    from cogmap.inference import to_pymdp

    jax.config.update("jax_enable_x64", True)
    model = tmaze_model()
    rng = np.random.default_rng(seed)
    P = len(enumerate_policies(model.num_controls, 2))
    E = rng.uniform(0.2, 3.0, size=P)
    selection = "stochastic" if sample else "deterministic"
    agent = to_pymdp(model, policy_len=2, gamma=4.0, alpha=3.0, E=jnp.asarray(E / E.sum())[None],
                     action_selection=selection, sampling_mode=MODES[sampling])
    state = loop.init(model, policy_len=2, gamma=4.0, E=E, alpha=3.0, sampling=sampling, sample=sample)
    prior = [jnp.asarray(model.live_D(f))[None] for f in range(2)]
    location, context = 0, int(rng.integers(2))
    key = jax.random.key(seed)
    for t in range(steps):
        obs = [int(rng.choice(n, p=model.live_A(m)[(slice(None), location, context)[: 1 + len(model.A_deps[m])]]))
               for m, n in enumerate(model.num_obs)]
        qs = pj.infer_states(agent, [jnp.array([o]) for o in obs], prior)
        q_pi, neg_efe = pj.infer_policies(agent, qs)
        key, k = jax.random.split(key)
        theirs = np.asarray(pj.sample_action(agent, q_pi, jax.random.split(k, 1)))[0]
        own = None if sample else loop.step(state, obs)[1].action  # its own choice (no randomness used)
        state, info = loop.step(state, obs, action=tuple(int(a) for a in theirs))
        for f in range(2):
            np.testing.assert_allclose(info.qs[f], np.asarray(qs[f])[0, -1], rtol=0, atol=1e-8)
        np.testing.assert_allclose(-info.G, np.asarray(neg_efe)[0], rtol=0, atol=1e-8)
        np.testing.assert_allclose(info.q_pi, np.asarray(q_pi)[0], rtol=0, atol=1e-8)
        yield t, agent, q_pi, info, theirs, own
        prior = pj.update_empirical_prior(agent, jnp.array([theirs]), qs)
        location = int(theirs[0])


@pytest.mark.parametrize("sampling", ["policy", "marginal"])
def test_habits_and_action_precision_match_pymdp_over_an_episode(sampling, pymdp_jit):
    """Posteriors, EFE and q(pi) with habits agree to 1e-8 over 20 steps given pymdp's sampled
    actions; the reported action probabilities match the frequencies of pymdp's own sampler."""
    import jax

    draws = 4000
    for t, agent, q_pi, info, _, _ in _episode(pymdp_jit, sampling, sample=True):
        if t not in (0, 7):
            continue
        keys = jax.random.split(jax.random.key(100 + t), draws)
        sampled = jax.jit(jax.vmap(lambda k, a=agent, q=q_pi: a.sample_action(q, rng_key=k[None])[0]))(keys)
        freq = np.zeros(info.action_probs.shape)
        np.add.at(freq, tuple(np.asarray(sampled).T), 1.0 / draws)
        sd = np.sqrt(info.action_probs * (1 - info.action_probs) / draws)
        assert np.all(np.abs(freq - info.action_probs) <= 5 * sd + 1e-3), (freq, info.action_probs)


@pytest.mark.parametrize("sampling", ["policy", "marginal"])
def test_deterministic_selection_matches_pymdp(sampling, pymdp_jit):
    """Without sampling the loop takes the action pymdp's deterministic Agent takes."""
    for _, _, _, info, theirs, own in _episode(pymdp_jit, sampling, sample=False, steps=8):
        assert own == tuple(int(a) for a in theirs)
        assert tuple(select_action(info.q_pi, info.policies, (4, 1), 3.0, sampling)) == own


def test_control_probabilities_against_enumeration():
    """Both modes against a direct computation from the definitions."""
    rng = np.random.default_rng(0)
    policies = enumerate_policies((3, 2), 2)
    q = rng.dirichlet(np.ones(len(policies)))
    alpha = 2.5
    # "policy": softmax(alpha ln q) over policies, summed over those sharing the first step
    w = q ** alpha / np.sum(q ** alpha)
    want = np.zeros((3, 2))
    for p, pol in zip(w, policies, strict=True):
        want[tuple(pol[0])] += p
    np.testing.assert_allclose(control_probabilities(q, policies, (3, 2), alpha, "policy"), want, atol=1e-14)
    # "marginal": each factor's marginal raised to alpha and renormalised, independently
    m0 = np.array([q[policies[:, 0, 0] == u].sum() for u in range(3)])
    m1 = np.array([q[policies[:, 0, 1] == u].sum() for u in range(2)])
    want = np.outer(m0 ** alpha / np.sum(m0 ** alpha), m1 ** alpha / np.sum(m1 ** alpha))
    np.testing.assert_allclose(control_probabilities(q, policies, (3, 2), alpha, "marginal"), want, atol=1e-14)
    # with alpha 1 the policy mode is the marginal of q(pi): what the loop reported before
    direct = np.zeros((3, 2))
    np.add.at(direct, (policies[:, 0, 0], policies[:, 0, 1]), q)
    np.testing.assert_allclose(control_probabilities(q, policies, (3, 2)), direct, atol=1e-15)


def test_habits_shift_the_choice():
    """A strong habit for one policy makes a deterministic agent take it when EFE is flat."""
    model = tmaze_model()
    P = len(enumerate_policies(model.num_controls, 1))
    for favourite in range(P):
        E = np.full(P, 1e-3)
        E[favourite] = 1.0
        state = loop.init(model, gamma=1e-3, E=E, sample=False)
        _, info = loop.step(state, [0, 0, 0])
        assert info.action[0] == favourite
        assert info.q_pi.argmax() == favourite


@pytest.mark.parametrize("kwargs, message", [
    (dict(alpha=0.0), "alpha"),
    (dict(alpha=float("inf")), "alpha"),
    (dict(alpha=True), "alpha"),
    (dict(sampling="full"), "sampling must be one of policy, marginal"),
    (dict(E=np.ones(3)), "E \\(habits\\) must be a vector of 4 weights"),
    (dict(E=np.array([1.0, 0.0, 1.0, 1.0])), "finite and positive"),
    (dict(E=np.ones(4), planner="mcts"), "needs planner 'enumerate'"),
    (dict(E=np.ones(3), backend="jax"), "E \\(habits\\) must be a vector of 4 weights"),
    (dict(alpha=-1.0, backend="jax"), "alpha"),
])
def test_bad_selection_settings_are_refused(kwargs, message):
    with pytest.raises(ValueError, match=message):
        loop.init(tmaze_model(), **kwargs)


@pytest.mark.parametrize("sampling, sample", [("policy", True), ("marginal", True), ("marginal", False)])
def test_the_jax_backend_selects_as_the_numpy_loop(sampling, sample):
    """Habits, alpha and both sampling modes on the JAX backend: q(pi), G and the action
    probabilities equal the numpy loop's to 1e-10 in float64 over an episode (same given actions);
    a deterministic JAX agent takes the numpy agent's action."""
    jax = pytest.importorskip("jax")
    model = tmaze_model()
    P = len(enumerate_policies(model.num_controls, 2))
    E = np.random.default_rng(2).uniform(0.2, 3.0, size=P)
    kwargs = dict(policy_len=2, gamma=4.0, E=E, alpha=2.5, sampling=sampling, sample=sample)
    rng = np.random.default_rng(5)
    with jax.enable_x64(True):
        ours, theirs = loop.init(model, **kwargs), loop.init(model, backend="jax", **kwargs)
        location, context = 0, 1
        for _ in range(10):
            obs = [int(rng.choice(n, p=model.live_A(m)[(slice(None), location, context)[: 1 + len(model.A_deps[m])]]))
                   for m, n in enumerate(model.num_obs)]
            if not sample:
                assert loop.step(theirs, obs)[1].action == loop.step(ours, obs)[1].action
            act = (int(rng.integers(4)), 0)
            ours, a = loop.step(ours, obs, action=act)
            theirs, b = loop.step(theirs, obs, action=act)
            np.testing.assert_allclose(b.q_pi, a.q_pi, rtol=0, atol=1e-10)
            np.testing.assert_allclose(b.G, a.G, rtol=0, atol=1e-10)
            np.testing.assert_allclose(b.action_probs, a.action_probs, rtol=0, atol=1e-10)
            location = act[0]


@pytest.mark.parametrize("sampling", ["policy", "marginal"])
def test_the_jax_agent_draws_from_the_probabilities_it_reports(sampling):
    jax = pytest.importorskip("jax")
    from cogmap import jax_agent

    model = tmaze_model()
    P = len(enumerate_policies(model.num_controls, 2))
    E = np.random.default_rng(3).uniform(0.2, 3.0, size=P)
    with jax.enable_x64(True):
        agent = jax_agent.build(model, policy_len=2, gamma=2.0, E=E, alpha=1.5, sampling=sampling)
        obs = jax_agent.observation(agent.config.layout, [0, 0, 0])
        draws = 4000
        states = jax.vmap(agent.init)(jax.random.split(jax.random.key(0), draws))
        _, info = jax.jit(jax.vmap(lambda s: agent.step(s, obs)))(states)
    probs = np.asarray(info.action_probs[0])
    freq = np.zeros(probs.shape)
    np.add.at(freq, tuple(np.asarray(info.action).T), 1.0 / draws)
    assert np.all(np.abs(freq - probs) <= 5 * np.sqrt(probs * (1 - probs) / draws) + 1e-3), (freq, probs)
    assert probs.max() < 0.99  # not a degenerate case

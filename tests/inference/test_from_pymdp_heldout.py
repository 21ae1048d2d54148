"""A held-out set of random pymdp 1.0 agents (transitions that depend on several factors, habits,
several modalities over several factors, stochastic and deterministic selection in both sampling
modes), loaded with from_pymdp and stepped beside pymdp for 20 steps."""

from __future__ import annotations

import numpy as np
import pytest

jax = pytest.importorskip("jax")
jnp = pytest.importorskip("jax.numpy")
pytest.importorskip("pymdp")

from pymdp.agent import Agent  # noqa: E402
from pymdp.control import get_marginals  # noqa: E402
from pymdp.maths import log_stable  # noqa: E402

from cogmap import loop  # noqa: E402
from cogmap.genmodel import compile  # noqa: E402
from cogmap.pymdp_import import from_pymdp  # noqa: E402

#: (seed, action_selection, sampling_mode): seeds used by no other test
HELD_OUT = [(101, "stochastic", "marginal"), (102, "stochastic", "full"),
            (103, "deterministic", "marginal"), (104, "deterministic", "full")]


def _dist(rng, *shape):
    x = rng.uniform(0.05, 1.0, size=shape) ** 2
    return x / x.sum(0)


def _random_agent(seed, selection, mode):
    """Three factors (the last uncontrolled), at least one depending on another, three modalities
    over random sets of factors, random preferences, initial beliefs and habits."""
    rng = np.random.default_rng(seed)
    ns = [int(rng.integers(2, 4)) for _ in range(3)]
    nc = [int(rng.integers(2, 4)), 2, 1]
    b_deps = [[0] + ([1] if rng.random() < 0.5 else []), [1, 0], [2] + ([1] if rng.random() < 0.5 else [])]
    a_deps = [sorted({0, int(rng.integers(1, 3))}), [int(rng.integers(0, 3))], [1, 2]]
    no = [int(rng.integers(2, 5)) for _ in a_deps]
    A = [_dist(rng, no[m], *(ns[f] for f in deps)) for m, deps in enumerate(a_deps)]
    B = [_dist(rng, ns[f], *(ns[d] for d in deps), nc[f]) for f, deps in enumerate(b_deps)]
    C = [rng.normal(0.0, 1.5, size=n) for n in no]
    D = [_dist(rng, n) for n in ns]
    settings = dict(policy_len=int(rng.integers(1, 3)), gamma=float(rng.uniform(1.0, 8.0)),
                    alpha=float(rng.uniform(0.5, 4.0)), action_selection=selection, sampling_mode=mode)

    def b(x):
        return jnp.asarray(x)[None]

    args = ([b(a) for a in A], [b(x) for x in B], [b(c) for c in C], [b(d) for d in D])
    kw = dict(A_dependencies=a_deps, B_dependencies=b_deps, num_controls=nc, **settings)
    P = Agent(*args, **kw).policies.policy_arr.shape[0]
    E = rng.uniform(0.2, 3.0, size=P)
    return Agent(*args, E=b(E / E.sum()), **kw), A, B, a_deps, b_deps


def _pymdp_action_probs(agent, q_pi, mode):
    """The distribution pymdp 1.0's sample_action / sample_policy draw from, over first-step controls."""
    policies = np.asarray(agent.policies.policy_arr)
    alpha = float(np.reshape(agent.alpha, (-1,))[0])
    nc = [int(u) for u in agent.num_controls]
    if mode == "marginal":  # each factor from softmax(alpha * log marginal)
        out = np.ones(())
        for m in get_marginals(q_pi, jnp.asarray(policies), nc):
            logits = alpha * np.asarray(log_stable(m))
            p = np.exp(logits - logits.max())
            out = np.multiply.outer(out, p / p.sum())
        return out
    logits = alpha * np.asarray(log_stable(q_pi))  # a policy from softmax(alpha * log q_pi)
    w = np.exp(logits - logits.max())
    out = np.zeros(nc)
    np.add.at(out, tuple(policies[:, 0, f] for f in range(len(nc))), w / w.sum())
    return out


@pytest.mark.parametrize("seed, selection, mode", HELD_OUT)
def test_held_out_pymdp_agent_gives_the_same_episode(seed, selection, mode, pymdp_jit):
    with jax.enable_x64(True):
        agent, A, B, a_deps, b_deps = _random_agent(seed, selection, mode)
        imported = from_pymdp(agent)
        model = compile(imported.spec)
        assert model.has_B_deps and model.B_deps == tuple(tuple(d) for d in b_deps)
        state = loop.init(model, **imported.settings)
        rng = np.random.default_rng(seed + 1000)
        s = [int(rng.integers(len(d))) for d in (np.asarray(x)[0] for x in agent.D)]
        prior = list(agent.D)
        key = jax.random.key(seed)
        for _ in range(20):
            obs = [int(rng.choice(A[m].shape[0], p=A[m][(slice(None),) + tuple(s[f] for f in deps)]))
                   for m, deps in enumerate(a_deps)]
            qs = pymdp_jit.infer_states(agent, [jnp.array([o]) for o in obs], prior)
            q_pi, neg_efe = pymdp_jit.infer_policies(agent, qs)
            key, k = jax.random.split(key)
            action = tuple(int(a) for a in np.asarray(pymdp_jit.sample_action(agent, q_pi, jax.random.split(k, 1)))[0])
            own = loop.step(state, obs)[1]
            state, info = loop.step(state, obs, action=action)
            for f in range(3):
                np.testing.assert_allclose(info.qs[f], np.asarray(qs[f])[0, -1], rtol=0, atol=1e-8)
            np.testing.assert_allclose(-info.G, np.asarray(neg_efe)[0], rtol=0, atol=1e-8)
            np.testing.assert_allclose(info.q_pi, np.asarray(q_pi)[0], rtol=0, atol=1e-8)
            np.testing.assert_allclose(info.action_probs, _pymdp_action_probs(agent, q_pi[0], mode),
                                       rtol=0, atol=1e-8)
            assert info.action == action  # the loop acted as it was told
            if selection == "deterministic":
                assert own.action == action  # and, left to itself, makes pymdp's choice
            prior = pymdp_jit.update_empirical_prior(agent, jnp.array([action]), qs)
            for f in range(3):
                np.testing.assert_allclose(state.prior[f], np.asarray(prior[f])[0], rtol=0, atol=1e-8)
            s = [int(rng.choice(B[f].shape[0], p=B[f][(slice(None),) + tuple(s[d] for d in deps) + (action[f],)]))
                 for f, deps in enumerate(b_deps)]

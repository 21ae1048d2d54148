"""from_pymdp: a pymdp 1.0 Agent loaded as a cogmap model and loop, checked step by step against pymdp."""

from __future__ import annotations

import numpy as np
import pytest

jax = pytest.importorskip("jax")
jnp = pytest.importorskip("jax.numpy")
pytest.importorskip("pymdp")

from pymdp.agent import Agent  # noqa: E402

from cogmap import loop  # noqa: E402
from cogmap.genmodel import compile  # noqa: E402
from cogmap.genmodel.demo_models import tmaze  # noqa: E402
from cogmap.inference import to_pymdp  # noqa: E402
from cogmap.pymdp_import import from_pymdp  # noqa: E402


@pytest.fixture(autouse=True)
def _x64():
    with jax.enable_x64(True):
        yield


def _pymdp_tmaze_agent(**kwargs):
    """pymdp's own T-maze (pymdp.envs.tmaze.TMaze) with preferences for reward and habits."""
    from pymdp.envs.tmaze import TMaze

    env = TMaze()
    A = [jnp.asarray(a)[None] for a in env.A]
    B = [jnp.asarray(b)[None] for b in env.B]
    D = [jnp.asarray(d)[None] for d in env.D]
    C = [jnp.zeros((1, a.shape[1])) for a in A]
    C[1] = jnp.asarray([[0.0, 3.0, -4.0]])
    agent = Agent(A, B, C, D, A_dependencies=env.A_dependencies, B_dependencies=env.B_dependencies, **kwargs)
    P = agent.policies.policy_arr.shape[0]
    E = np.random.default_rng(1).uniform(0.2, 3.0, size=P)
    return Agent(A, B, C, D, E=jnp.asarray(E / E.sum())[None], A_dependencies=env.A_dependencies,
                 B_dependencies=env.B_dependencies, **kwargs), env


def _run(pj, agent, env, steps=20, seed=0):
    """Step pymdp's agent and the loaded cogmap loop side by side, giving both pymdp's actions."""
    imported = from_pymdp(agent)
    state = loop.init(compile(imported.spec), **imported.settings)
    rng = np.random.default_rng(seed)
    A = [np.asarray(a) for a in env.A]
    B = [np.asarray(b) for b in env.B]
    s = [0, int(rng.integers(2))]  # centre, random reward condition
    prior = list(agent.D)
    key = jax.random.key(seed)
    for _ in range(steps):
        obs = [int(rng.choice(A[m].shape[0], p=A[m][(slice(None),) + tuple(s[f] for f in deps)]))
               for m, deps in enumerate(env.A_dependencies)]
        qs = pj.infer_states(agent, [jnp.array([o]) for o in obs], prior)
        q_pi, neg_efe = pj.infer_policies(agent, qs)
        key, k = jax.random.split(key)
        action = np.asarray(pj.sample_action(agent, q_pi, jax.random.split(k, 1)))[0]
        own = loop.step(state, obs)[1].action
        state, info = loop.step(state, obs, action=tuple(int(a) for a in action))
        yield qs, q_pi, neg_efe, action, own, info
        prior = pj.update_empirical_prior(agent, jnp.array([action]), qs)
        s = [int(rng.choice(B[f].shape[0], p=B[f][:, s[f], int(action[f])])) for f in range(2)]


@pytest.mark.parametrize("selection, mode", [("stochastic", "marginal"), ("stochastic", "full"),
                                             ("deterministic", "marginal"), ("deterministic", "full")])
def test_pymdp_tmaze_agent_loaded_gives_the_same_episode(selection, mode, pymdp_jit):
    """State posteriors, negative EFE and q(pi) to 1e-8 over a 20-step episode; a deterministic
    agent makes pymdp's choice; a stochastic one reports pymdp's sampling distribution."""
    agent, env = _pymdp_tmaze_agent(policy_len=2, gamma=4.0, alpha=2.0, action_selection=selection,
                                    sampling_mode=mode)
    for t, (qs, q_pi, neg_efe, action, own, info) in enumerate(_run(pymdp_jit, agent, env)):
        for f in range(2):
            np.testing.assert_allclose(info.qs[f], np.asarray(qs[f])[0, -1], rtol=0, atol=1e-8)
        np.testing.assert_allclose(-info.G, np.asarray(neg_efe)[0], rtol=0, atol=1e-8)
        np.testing.assert_allclose(info.q_pi, np.asarray(q_pi)[0], rtol=0, atol=1e-8)
        if selection == "deterministic":
            assert own == tuple(int(a) for a in action)
        elif t in (0, 3):  # pymdp's own sampler, many draws, against the reported probabilities
            draws = 3000
            keys = jax.random.split(jax.random.key(50 + t), draws)
            sampled = np.asarray(jax.jit(jax.vmap(lambda k, q=q_pi: agent.sample_action(q, rng_key=k[None])[0]))(keys))
            freq = np.zeros(info.action_probs.shape)
            np.add.at(freq, tuple(sampled.T), 1.0 / draws)
            sd = np.sqrt(info.action_probs * (1 - info.action_probs) / draws)
            assert np.all(np.abs(freq - info.action_probs) <= 5 * sd + 1e-3)


def test_round_trip_keeps_the_model_and_the_counts():
    """to_pymdp then from_pymdp returns the same arrays, Dirichlet counts included."""
    from cogmap.genmodel import Factor, Modality, ModelSpec

    rng = np.random.default_rng(0)

    pA = {"o": rng.uniform(0.5, 2.0, size=(3, 4))}
    pB = {"s": rng.uniform(0.5, 2.0, size=(4, 4, 2))}
    A = pA["o"] / pA["o"].sum(0)
    B = pB["s"] / pB["s"].sum(0)
    small = compile(ModelSpec(factors=[Factor("s", 4, num_controls=2)], modalities=[Modality("o", 3, ("s",))],
                              A={"o": A}, B={"s": B}, C={"o": np.array([0.0, 1.0, -1.0])}, pA=pA, pB=pB))
    back = compile(from_pymdp(to_pymdp(small, gamma=2.5, use_param_info_gain=True)).spec)
    np.testing.assert_allclose(back.live_A(0), small.live_A(0), atol=1e-14)
    np.testing.assert_allclose(back.live_B(0), small.live_B(0), atol=1e-14)
    np.testing.assert_allclose(back.live_pA(0), small.live_pA(0), atol=1e-14)
    np.testing.assert_allclose(back.live_pB(0), small.live_pB(0), atol=1e-14)
    np.testing.assert_allclose(back.live_C(0), small.live_C(0), atol=1e-14)
    settings = from_pymdp(to_pymdp(small, gamma=2.5, use_param_info_gain=True)).settings
    assert settings["gamma"] == 2.5 and settings["scheme"] == "fpi"


def test_what_cannot_be_loaded_is_refused_by_name():
    model = tmaze()
    coupled = to_pymdp(model)
    B = [jnp.asarray(np.ones((1, 4, 4, 2, 4)) / 4), coupled.B[1]]
    dependent = Agent(coupled.A, B, coupled.C, coupled.D, A_dependencies=[[0], [0, 1], [0, 1]],
                      B_dependencies=[[0, 1], [1]], num_controls=[4, 1])
    assert compile(from_pymdp(dependent).spec).B_deps == ((0, 1), (1,))  # B_dependencies load now
    agents = {
        "learn_E": to_pymdp(model, learn_E=True),
        "custom policies": to_pymdp(model, policies=np.zeros((2, 1, 2), dtype=int)),
    }
    for message, agent in agents.items():  # built by pymdp first: only from_pymdp may refuse
        with pytest.raises(ValueError, match=message):
            from_pymdp(agent)
    with pytest.raises(ValueError, match="no batch entry 3"):
        from_pymdp(to_pymdp(model), index=3)

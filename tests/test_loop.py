"""The agent loop for any compiled model: agreement with pymdp 1.0's Agent, learning, errors."""

from __future__ import annotations

import numpy as np
import pytest

from cogmap import loop
from cogmap.genmodel import Factor, Modality, ModelSpec, SpecError, compile
from cogmap.genmodel.demo_models import corridor, tmaze
from cogmap.genmodel.dirichlet import update_pA
from cogmap.inference.learning import update_pB


def _tmaze_with_preferences():
    m = tmaze()
    m.C[1][:3] = [0.0, 3.0, -6.0]
    return m


@pytest.mark.parametrize("gamma", [1.0, 16.0])
def test_loop_policy_posterior_matches_pymdp_agent_over_an_episode(gamma):
    jax = pytest.importorskip("jax")
    jnp = pytest.importorskip("jax.numpy")
    pytest.importorskip("pymdp")
    from cogmap.inference import to_pymdp

    jax.config.update("jax_enable_x64", True)
    model = _tmaze_with_preferences()
    agent = to_pymdp(model, policy_len=2, gamma=gamma)
    state = loop.init(model, policy_len=2, gamma=gamma, sample=False)
    prior = [jnp.asarray(model.live_D(f))[None] for f in range(2)]
    rng = np.random.default_rng(3)
    location, context = 0, int(rng.integers(2))

    def draw(m):  # an outcome the model can produce at the true location and context
        p = model.live_A(m)[:, location, context]
        return int(rng.choice(p.size, p=p / p.sum()))

    for _ in range(3):
        obs = [location, draw(1), draw(2)]
        qs = agent.infer_states([jnp.array([o]) for o in obs], prior)
        q_pi, neg_efe = agent.infer_policies(qs)
        state, info = loop.step(state, obs)
        np.testing.assert_allclose(info.q_pi, np.asarray(q_pi)[0], atol=1e-6)
        np.testing.assert_allclose(info.G, -np.asarray(neg_efe)[0], atol=1e-6)
        for f in range(2):
            np.testing.assert_allclose(info.qs[f], np.asarray(qs[f])[0, -1], atol=1e-6)
        prior = agent.update_empirical_prior(jnp.array([info.action]), qs)
        location = info.action[0]


def test_loop_learns_A_and_B_like_the_pure_updates():
    spec_model = corridor(np.random.default_rng(0), n=4)
    n, u = spec_model.num_states[0], spec_model.num_controls[0]
    model = compile(ModelSpec(
        factors=[Factor("s", n, num_controls=u)], modalities=[Modality("o", spec_model.num_obs[0], ("s",))],
        A={"o": spec_model.live_A(0)}, B={"s": spec_model.live_B(0)},
        pA={"o": 2 * spec_model.live_A(0) + 0.1}, pB={"s": 2 * spec_model.live_B(0) + 0.1},
    ))
    pA0, pB0 = model.live_pA(0).copy(), model.live_pB(0).copy()
    state = loop.init(model, learn_A=True, learn_B=True, lr_A=0.5, lr_B=2.0, seed=1)
    state, first = loop.step(state, [1])
    state, second = loop.step(state, [2])
    want_A = update_pA(update_pA(pA0, 1, [first.qs[0]], 0.5), 2, [second.qs[0]], 0.5)
    np.testing.assert_allclose(model.live_pA(0), want_A, atol=1e-12)
    want_B = update_pB(pB0, second.qs[0], first.qs[0], first.action[0], lr=2.0)
    np.testing.assert_allclose(model.live_pB(0), want_B, atol=1e-12)
    np.testing.assert_allclose(model.live_B(0).sum(axis=0), 1.0, atol=1e-12)


@pytest.mark.parametrize(
    "kwargs, error, message",
    [
        (dict(scheme="nope"), Exception, "nope"),
        (dict(planner="astar"), ValueError, "unknown planner"),
        (dict(gamma=0.0), ValueError, "gamma"),
        (dict(gamma=float("nan")), ValueError, "gamma"),
        (dict(policy_len=0), ValueError, "policy_len"),
        (dict(objective="greedy"), ValueError, "unknown objective"),
        (dict(learn_A=True), SpecError, "learn_A needs"),
        (dict(scheme="exact", num_iter=4), ValueError,
         r"^inference scheme 'exact' has no option 'num_iter' \(its options: smooth, max_joint\)$"),
        (dict(scheme="filter", tol=0.1), ValueError,
         r"^inference scheme 'filter' has no option 'tol' \(it takes no options\)$"),
        (dict(scheme="fpi", observations=[0]), ValueError, "'observations' is an argument of every inference scheme"),
    ],
)
def test_loop_refuses_bad_settings_with_a_message(kwargs, error, message):
    with pytest.raises(error, match=message):
        loop.init(tmaze(), **kwargs)


def test_loop_refuses_a_wrong_observation_and_a_non_model():
    state = loop.init(tmaze())
    with pytest.raises(ValueError, match="one entry per modality"):
        loop.step(state, [0, 0])
    with pytest.raises(TypeError, match="compiled Model"):
        loop.init({"A": 1})
    state, info = loop.step(state, {"where": 0, "reward": 0, "cue": 1})  # by name; missing ones allowed
    assert len(info.action) == 2

"""Fitting agents to behaviour: the likelihood of choices, its gradients, episodes as one scan, MAP recovery."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from cogmap import fit, jax_agent, loop
from cogmap.envs import jax_worlds
from cogmap.genmodel import Factor, Modality, ModelSpec, compile


@pytest.fixture(autouse=True)
def x64():
    with jax.enable_x64(True):
        yield


def _learning_tmaze():
    """The T-maze with Dirichlet counts on every likelihood (an agent that learns A)."""
    base = jax_worlds.tmaze_model()
    spec = ModelSpec(
        factors=[Factor("location", 4, num_controls=4), Factor("context", 2)],
        modalities=[Modality("where", 4, ("location",)), Modality("reward", 3, ("location", "context")),
                    Modality("cue", 2, ("location", "context"))],
        A={"where": base.live_A(0), "reward": base.live_A(1), "cue": base.live_A(2)},
        B={"location": base.live_B(0), "context": base.live_B(1)},
        C={"reward": base.live_C(1)},
        D={"location": base.live_D(0)},
        pA={"where": 8 * base.live_A(0) + 0.5, "reward": 2 * base.live_A(1) + 0.5, "cue": 2 * base.live_A(2) + 0.5},
    )
    return compile(spec)


def test_the_likelihood_is_the_sum_of_the_numpy_loops_action_log_probabilities():
    model = jax_worlds.tmaze_model()
    agent = jax_agent.build(model, policy_len=2, gamma=3.0)
    data = fit.simulate(agent, jax_worlds.tmaze_world(), jax.random.key(4), trials=3, steps=2)
    total = 0.0
    for k in range(3):
        state = loop.init(jax_worlds.tmaze_model(), policy_len=2, gamma=3.0)
        for t in range(2):
            obs = [int(np.argmax(np.asarray(o[k, t]))) for o in data.obs]
            choice = tuple(int(a) for a in np.asarray(data.actions[k, t]))
            state, info = loop.step(state, obs, action=choice)
            total += np.log(info.action_probs[choice])
    assert abs(float(fit.log_likelihood(agent, data)) - total) < 1e-10


def test_gradients_match_central_finite_differences():
    agent = jax_agent.build(_learning_tmaze(), policy_len=1, gamma=2.0, learn_A=True, lr_A=0.8,
                            objective=fit_objective())
    data = fit.simulate(agent, jax_worlds.tmaze_world(), jax.random.key(7), trials=2, steps=2)
    free = fit.check_free([fit.Free("gamma"), fit.Free("C:1", fit.Normal(1.0, 1.0)), fit.Free("lr_A"),
                           fit.Free("pA:1"), fit.Free("w:state_info_gain", fit.Normal(1.0, 1.0)),
                           fit.Free("alpha")], agent)
    theta = fit.unconstrained(free, jnp.array([2.0, 1.2, 0.8, 1.5, 0.9, 1.3]))

    def ll(th):
        return fit.log_likelihood(agent, data, fit.apply(agent.params, free, th))

    g = np.asarray(jax.grad(ll)(theta))
    h = 1e-5
    for i in range(len(free)):
        e = jnp.zeros_like(theta).at[i].set(h)
        fd = (float(ll(theta + e)) - float(ll(theta - e))) / (2 * h)
        assert abs(g[i] - fd) <= 1e-6 * max(abs(fd), 1e-3), (free[i].name, g[i], fd)
    assert np.all(np.abs(g) > 1e-4), "every parameter moves the likelihood"


def fit_objective():
    from cogmap.planning import efe

    return efe.objective([(efe.observation_preference, 1.0), (efe.state_info_gain, 1.0), (efe.a_novelty, 1.0)])


def test_an_episode_is_one_scan_and_agrees_with_stepping_by_hand():
    agent = jax_agent.build(jax_worlds.tmaze_model(), policy_len=2, gamma=4.0)
    world = jax_worlds.tmaze_world()
    tr = jax.jit(lambda k: jax_agent.rollout(agent, world, k, 3))(jax.random.key(2))
    state = agent.init(jax.random.split(jax.random.key(2), 3)[0])
    for t in range(3):
        state, info = agent.step(state, tuple(o[t] for o in tr.obs))
        assert np.array_equal(np.asarray(info.action), np.asarray(tr.actions[t]))
        np.testing.assert_allclose(np.asarray(info.q_pi), np.asarray(tr.info.q_pi[t]), atol=1e-12)
    # the world follows B: the location after each move is the move's target (B is 90 % right)
    where = np.asarray(tr.obs[0]).argmax(axis=1)
    assert where[0] == 0, "every episode starts at the centre"


def test_map_recovers_the_policy_precision_of_simulated_subjects():
    agent = jax_agent.build(jax_worlds.tmaze_model(), policy_len=2, gamma=2.0)
    free = [fit.Free("gamma", fit.LogNormal(np.log(2.0), 0.6))]
    true = np.exp(np.random.default_rng(0).normal(np.log(2.0), 0.5, 12))

    def sim(g, k):
        return fit.simulate(agent, jax_worlds.tmaze_world(), k, trials=60, steps=2,
                            params=fit.apply(agent.params, free, jnp.log(g)[None]))

    data = jax.jit(jax.vmap(sim))(jnp.asarray(true), jax.random.split(jax.random.key(1), 12))
    res = fit.fit_map(agent, free, data, iterations=150)
    est = res.values[:, 0]
    assert np.corrcoef(est, true)[0, 1] > 0.85
    assert np.median(np.abs(est - true) / true) < 0.2
    assert np.all(res.trace[-1] < res.trace[0])
    for i in range(2):  # the estimate is a stationary point of the log posterior
        subject = jax.tree_util.tree_map(lambda x, i=i: x[i], data)
        g = jax.grad(lambda th, s=subject: fit.log_posterior(agent, free, th, s))(jnp.asarray(res.theta[i]))
        assert np.all(np.abs(np.asarray(g)) < 1e-2)


def test_bad_free_parameters_are_refused():
    agent = jax_agent.build(jax_worlds.tmaze_model())
    with pytest.raises(ValueError, match="unknown free parameter"):
        fit.check_free([fit.Free("beta")], agent)
    with pytest.raises(ValueError, match="3 modalities"):
        fit.check_free([fit.Free("C:5", fit.Normal())], agent)
    with pytest.raises(ValueError, match="no Dirichlet counts"):
        fit.check_free([fit.Free("pA:0")], agent)
    with pytest.raises(ValueError, match="needs a LogNormal prior"):
        fit.check_free([fit.Free("gamma", fit.Normal())], agent)
    with pytest.raises(ValueError, match="repeat"):
        fit.check_free([fit.Free("gamma"), fit.Free("gamma")], agent)
    data = fit.simulate(agent, jax_worlds.tmaze_world(), jax.random.key(0), trials=2, steps=2)
    with pytest.raises(ValueError, match="subjects stacked"):
        fit.fit_map(agent, [fit.Free("gamma")], data)


def test_diagnostics_on_chains_with_known_answers():
    from cogmap.inference.mcmc_diagnostics import effective_sample_size, split_rhat

    rng = np.random.default_rng(0)
    iid = rng.normal(size=(4, 2000))
    assert abs(float(split_rhat(iid)) - 1.0) < 0.01
    assert abs(float(effective_sample_size(iid)) / 8000 - 1.0) < 0.1
    rho, x = 0.8, np.zeros((4, 4000))
    for t in range(1, 4000):
        x[:, t] = rho * x[:, t - 1] + rng.normal(size=4)
    ess = float(effective_sample_size(x))
    assert abs(ess / (16000 * (1 - rho) / (1 + rho)) - 1.0) < 0.25  # the AR(1) closed form
    apart = iid + np.array([0.0, 0.0, 0.0, 3.0])[:, None]
    assert float(split_rhat(apart)) > 1.5
    with pytest.raises(ValueError, match="at least 4 samples"):
        split_rhat(np.zeros((2, 3)))


def _grid_posterior(agent, free, subject, lo=-3.0, hi=4.0, n=701):
    """Log posterior of one scalar parameter on a grid of the unconstrained scale (quadrature reference)."""
    th = np.linspace(lo, hi, n)
    lp = np.asarray(jax.vmap(lambda t: fit.log_posterior(agent, free, t[None], subject))(jnp.asarray(th)))
    return th, lp


def test_nuts_and_laplace_agree_with_quadrature_of_the_posterior():
    agent = jax_agent.build(jax_worlds.tmaze_model(), policy_len=2, gamma=2.0)
    free = (fit.Free("gamma", fit.LogNormal(np.log(2.0), 0.6)),)
    data = fit.simulate_subjects(fit.Candidate("efe", agent, free), jax_worlds.tmaze_world(), jax.random.key(5),
                                 np.array([[2.5]]), trials=20, steps=2)
    post = fit.fit_nuts(agent, free, data, jax.random.key(6), chains=2, warmup=100, samples=150)
    evidence = fit.laplace_evidence(agent, free, data, iterations=200)
    for i in range(1):
        subject = jax.tree_util.tree_map(lambda x, i=i: x[i], data)
        th, lp = _grid_posterior(agent, free, subject)
        w = np.exp(lp - lp.max())
        step = th[1] - th[0]
        exact_mean = float((np.exp(th) * w).sum() / w.sum())
        log_z = float(lp.max() + np.log(w.sum() * step))
        se = post.sd[i, 0] / np.sqrt(post.ess[i, 0])
        assert abs(post.mean[i, 0] - exact_mean) < 4 * se + 1e-3, (post.mean[i, 0], exact_mean, se)
        assert post.rhat[i, 0] < 1.05
        assert abs(evidence[i] - log_z) < 0.2, (evidence[i], log_z)


def test_model_comparison_recovers_the_generating_agent():
    from cogmap.planning import efe

    free = (fit.Free("gamma", fit.LogNormal(np.log(2.0), 0.6)),)
    m = jax_worlds.tmaze_model
    utility = efe.objective([(efe.observation_preference, 1.0)])
    cands = [fit.Candidate("efe", jax_agent.build(m(), policy_len=2, gamma=2.0), free),
             fit.Candidate("utility only", jax_agent.build(m(), policy_len=2, gamma=2.0, objective=utility), free)]
    M = fit.confusion(cands, jax_worlds.tmaze_world(), jax.random.key(0),
                      lambda i, rng: np.exp(rng.normal(np.log(2.0), 0.4, (4, 1))), subjects=4, trials=30, steps=2,
                      iterations=100)
    assert M.shape == (2, 2) and np.allclose(M.sum(axis=1), 1.0)
    assert np.all(np.diag(M) >= 3 / 4), M
    with pytest.raises(ValueError, match="at least two candidates"):
        fit.compare(cands[:1], None)

"""Transitions that depend on several factors (pymdp 1.0's ``B_dependencies``): prediction, exact
Bayes, the free energy, vmp and a side-by-side episode against pymdp."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from cogmap.genmodel import compile
from cogmap.genmodel.spec import Factor, Modality, ModelSpec, SpecError
from cogmap.inference.base import InferenceError, predict_factorised, prepare
from cogmap.inference.exact import exact
from cogmap.inference.fpi import fpi
from cogmap.inference.free_energy import free_energy_terms, window_free_energy
from cogmap.inference.mean_field import vmp
from cogmap.inference.message_passing import mmp, vmp_pymdp


def _rnd(rng, *shape):
    x = rng.random(shape) + 0.05
    return x / x.sum(axis=0, keepdims=True)


def _model(seed=0, pB=False):
    """Three factors: 'a' (3 states) depends on itself; 'b' (2) on ('a', 'b'); 'c' (2) on ('c', 'b')."""
    rng = np.random.default_rng(seed)
    B = {"a": _rnd(rng, 3, 3, 2), "b": _rnd(rng, 2, 3, 2, 2), "c": _rnd(rng, 2, 2, 2, 1)}
    spec = ModelSpec(
        [Factor("a", 3, 2), Factor("b", 2, 2, depends_on=("a", "b")), Factor("c", 2, 1, depends_on=("c", "b"))],
        [Modality("o1", 3, ("a", "b")), Modality("o2", 2, ("c",))],
        A={"o1": _rnd(rng, 3, 3, 2), "o2": _rnd(rng, 2, 2)}, B=B,
        D={"a": _rnd(rng, 3), "b": _rnd(rng, 2), "c": _rnd(rng, 2)},
        pB={k: v * 5 for k, v in B.items()} if pB else {},
    )
    return compile(spec), B


def _transition(B, deps, f, u, s_next, s_prev):
    return B[f][(s_next[f],) + tuple(s_prev[d] for d in deps[f]) + (u[f],)]


NAMES = ("a", "b", "c")
DEPS = ((0,), (0, 1), (2, 1))


def test_compiled_model_carries_the_dependencies():
    m, B = _model()
    assert m.B_deps == DEPS and m.has_B_deps
    np.testing.assert_array_equal(m.live_B(1), B["b"])
    single = compile(ModelSpec([Factor("x", 2)], [Modality("o", 2, ("x",))], A={"o": np.eye(2)},
                               B={"x": np.eye(2)[:, :, None]}))
    assert single.B_deps == ((0,),) and not single.has_B_deps


def test_mean_field_prediction_is_the_marginal_of_the_exact_joint_prediction():
    """From a product prior, the exact joint prediction marginalised equals predict_factorised."""
    m, B = _model(1)
    rng = np.random.default_rng(2)
    qs = [_rnd(rng, 3), _rnd(rng, 2), _rnd(rng, 2)]
    Bl = [B[n] for n in NAMES]
    for u in itertools.product(range(2), range(2), range(1)):
        joint = np.zeros((3, 2, 2))
        for s_prev in itertools.product(range(3), range(2), range(2)):
            p_prev = qs[0][s_prev[0]] * qs[1][s_prev[1]] * qs[2][s_prev[2]]
            for s_next in itertools.product(range(3), range(2), range(2)):
                joint[s_next] += p_prev * np.prod([_transition(Bl, DEPS, f, u, s_next, s_prev) for f in range(3)])
        pred = predict_factorised(m, qs, u)
        for f in range(3):
            marg = joint.sum(axis=tuple(g for g in range(3) if g != f))
            np.testing.assert_allclose(pred[f], marg, rtol=0, atol=1e-14)


def test_exact_matches_enumeration_over_state_paths():
    m, B = _model(3)
    Bl = [B[n] for n in NAMES]
    A1, A2 = m.live_A(0), m.live_A(1)
    prior = [m.live_D(f) for f in range(3)]
    obs = [[0, 1], [2, 0], [1, 1]]
    acts = [(1, 0, 0), (0, 1, 0)]
    states = list(itertools.product(range(3), range(2), range(2)))
    marg = [[np.zeros(n) for n in (3, 2, 2)] for _ in range(3)]
    total = 0.0
    for path in itertools.product(states, repeat=3):
        p = np.prod([prior[f][path[0][f]] for f in range(3)])
        for t in range(3):
            if t:
                p *= np.prod([_transition(Bl, DEPS, f, acts[t - 1], path[t], path[t - 1]) for f in range(3)])
            s = path[t]
            p *= A1[obs[t][0], s[0], s[1]] * A2[obs[t][1], s[2]]
        total += p
        for t in range(3):
            for f in range(3):
                marg[t][f][path[t][f]] += p
    post, info = exact(m, prior, obs, acts)
    assert info.total_free_energy == pytest.approx(-np.log(total), abs=1e-12)
    for t in range(3):
        for f in range(3):
            np.testing.assert_allclose(info.history[t][f], marg[t][f] / total, rtol=0, atol=1e-12)
    # filtering: the last-step marginals are those of the paths' last states too
    for f in range(3):
        np.testing.assert_allclose(post[f], marg[2][f] / total, rtol=0, atol=1e-12)


def test_free_energy_transition_term_with_dependencies():
    m, B = _model(4)
    rng = np.random.default_rng(5)
    prior = [m.live_D(f) for f in range(3)]
    obs = [[0, 1], [2, 0]]
    acts = [(1, 1, 0)]
    q = [[_rnd(rng, 3), _rnd(rng, 2), _rnd(rng, 2)] for _ in range(2)]
    prob = prepare(m, prior, obs, acts)
    terms = free_energy_terms(m, prob, prob.prior, q)
    logB = [np.log(np.maximum(B[n][..., u], np.finfo(float).eps)) for n, u in zip(NAMES, acts[0], strict=True)]
    direct = sum(float(q[1][f] @ np.log(q[1][f])) for f in range(3))
    direct -= float(q[1][0] @ logB[0] @ q[0][0])
    direct -= float(np.einsum("nab,n,a,b->", logB[1], q[1][1], q[0][0], q[0][1]))
    direct -= float(np.einsum("ncb,n,c,b->", logB[2], q[1][2], q[0][2], q[0][1]))
    A1, A2 = m.live_A(0), m.live_A(1)
    direct -= float(np.einsum("ab,a,b->", np.log(A1[2]), q[1][0], q[1][1])) + float(q[1][2] @ np.log(A2[0]))
    assert terms[1] == pytest.approx(direct, abs=1e-12)
    assert window_free_energy(m, prior, obs, acts, q) == pytest.approx(terms.sum(), abs=1e-12)


def test_vmp_descends_and_bounds_exact():
    m, _ = _model(6)
    prior = [m.live_D(f) for f in range(3)]
    obs = [[0, 1], [2, 0], [1, 1], [0, 0]]
    acts = [(1, 0, 0), (0, 1, 0), (1, 1, 0)]
    exact_fe = exact(m, prior, obs, acts)[1].total_free_energy
    fes = [vmp(m, prior, obs, acts, num_iter=k)[1].total_free_energy for k in (1, 2, 4, 8, 16)]
    assert all(b <= a + 1e-12 for a, b in zip(fes, fes[1:], strict=False))
    assert fes[-1] >= exact_fe - 1e-12
    _, info = vmp(m, prior, obs, acts)
    assert info.total_free_energy == pytest.approx(window_free_energy(m, prior, obs, acts, info.history[-4:]),
                                                   abs=1e-10)


def test_vmp_update_is_the_coordinate_minimiser():
    """At vmp's fixed point no perturbation of a single marginal lowers the window free energy."""
    m, _ = _model(10)
    prior = [m.live_D(f) for f in range(3)]
    obs = [[0, 1], [2, 0], [1, 1]]
    acts = [(1, 0, 0), (0, 1, 0)]
    _, info = vmp(m, prior, obs, acts, num_iter=200, tol=1e-14)
    q = [list(h) for h in info.history]
    best = window_free_energy(m, prior, obs, acts, q)
    rng = np.random.default_rng(0)
    for t in range(3):
        for f in range(3):
            for _ in range(5):
                trial = [list(h) for h in q]
                x = trial[t][f] * np.exp(0.05 * rng.standard_normal(trial[t][f].size))
                trial[t][f] = x / x.sum()
                assert window_free_energy(m, prior, obs, acts, trial) >= best - 1e-12


@pytest.mark.parametrize(("method", "ours"), (("vmp", vmp_pymdp), ("mmp", mmp)))
@pytest.mark.parametrize("seed", (0, 1))
def test_message_passing_matches_pymdp_with_b_dependencies(method, ours, seed):
    jax = pytest.importorskip("jax")
    jnp = pytest.importorskip("jax.numpy")
    pytest.importorskip("pymdp")
    from pymdp.inference import update_posterior_states

    m, _ = _model(20 + seed)
    rng = np.random.default_rng(seed)
    T = 4
    obs = [[int(rng.integers(3)), int(rng.integers(2))] for _ in range(T)]
    act = [(int(rng.integers(2)), int(rng.integers(2)), 0) for _ in range(T - 1)]
    prior = [m.live_D(f) for f in range(3)]
    with jax.enable_x64(True):
        ref = update_posterior_states(
            [jnp.asarray(m.live_A(k)) for k in range(2)], [jnp.asarray(m.live_B(f)) for f in range(3)],
            [jnp.asarray(np.eye(m.num_obs[k])[[o[k] for o in obs]]) for k in range(2)], jnp.asarray(np.array(act)),
            prior=[jnp.asarray(p) for p in prior], num_iter=8, method=method,
            A_dependencies=[list(d) for d in m.A_deps], B_dependencies=[list(d) for d in DEPS])
    q, info = ours(m, prior, obs, act, num_iter=8)
    for f in range(3):
        np.testing.assert_allclose(np.array([h[f] for h in info.history]), np.asarray(ref[f]), rtol=0, atol=1e-10)
        np.testing.assert_allclose(q[f], np.asarray(ref[f])[-1], rtol=0, atol=1e-10)


def test_single_factor_prediction_refuses():
    m, _ = _model()
    with pytest.raises(SpecError, match="B_dependencies"):
        m.predict(1, m.live_D(1), 0)
    with pytest.raises(InferenceError, match="B_dependencies"):
        from cogmap.inference.base import dense_transition

        dense_transition(m, 1, 0)


def test_fpi_runs_and_uses_the_mean_field_prediction():
    m, _ = _model(7)
    prior = [m.live_D(f) for f in range(3)]
    _, info = fpi(m, prior, [[0, 1], [2, 0]], [(1, 0, 0)])
    step0 = info.history[0]
    pri1 = predict_factorised(m, list(step0), (1, 0, 0))
    _, info1 = fpi(m, pri1, [[2, 0]])
    for f in range(3):
        np.testing.assert_allclose(info.history[1][f], info1.history[0][f], rtol=0, atol=1e-15)


# -- against pymdp 1.0 ------------------------------------------------------------------------
def _pymdp_agent(jnp, Agent, seed=0, **kwargs):
    rng = np.random.default_rng(seed)
    A = [_rnd(rng, 3, 3, 2), _rnd(rng, 2, 2)]
    B = [_rnd(rng, 3, 3, 3), _rnd(rng, 2, 3, 2, 2), _rnd(rng, 2, 2, 2, 1)]
    C = [np.array([0.0, 1.5, -1.0]), np.array([0.5, 0.0])]
    D = [_rnd(rng, 3), _rnd(rng, 2), _rnd(rng, 2)]
    def b(x):
        return jnp.asarray(x)[None]

    agent = Agent([b(a) for a in A], [b(x) for x in B], [b(c) for c in C], [b(d) for d in D],
                  A_dependencies=[[0, 1], [2]], B_dependencies=[[0], [0, 1], [2, 1]], **kwargs)
    return agent, A, B


@pytest.mark.parametrize("param_info_gain", [False, True])
def test_fpi_episode_matches_pymdp_with_b_dependencies(param_info_gain, pymdp_jit):
    jax = pytest.importorskip("jax")
    jnp = pytest.importorskip("jax.numpy")
    pytest.importorskip("pymdp")
    from pymdp.agent import Agent

    from cogmap import loop
    from cogmap.pymdp_import import from_pymdp

    with jax.enable_x64(True):
        settings = dict(policy_len=2, gamma=4.0, action_selection="deterministic")
        agent, A, B = _pymdp_agent(jnp, Agent, **settings)
        if param_info_gain:  # Dirichlet counts of B (positive where B is) for the parameter information gain
            rng = np.random.default_rng(11)
            pB = [jnp.asarray(np.asarray(x)[0] * rng.uniform(1, 5, size=np.asarray(x)[0].shape))[None]
                  for x in agent.B]
            agent, A, B = _pymdp_agent(jnp, Agent, pB=pB, use_param_info_gain=True, **settings)
        imported = from_pymdp(agent)
        model = compile(imported.spec)
        assert model.B_deps == ((0,), (0, 1), (2, 1))
        state = loop.init(model, **imported.settings)
        rng = np.random.default_rng(0)
        s = [0, 1, 0]
        prior = list(agent.D)
        for _ in range(20):
            obs = [int(rng.choice(3, p=A[0][:, s[0], s[1]])), int(rng.choice(2, p=A[1][:, s[2]]))]
            qs = pymdp_jit.infer_states(agent, [jnp.array([o]) for o in obs], prior)
            q_pi, neg_efe = pymdp_jit.infer_policies(agent, qs)
            action = np.asarray(pymdp_jit.sample_action(agent, q_pi, jax.random.split(jax.random.key(0), 1)))[0]
            state, info = loop.step(state, obs, action=tuple(int(a) for a in action))
            for f in range(3):
                np.testing.assert_allclose(info.qs[f], np.asarray(qs[f])[0, -1], rtol=0, atol=1e-8)
            np.testing.assert_allclose(-info.G, np.asarray(neg_efe)[0], rtol=0, atol=1e-8)
            np.testing.assert_allclose(info.q_pi, np.asarray(q_pi)[0], rtol=0, atol=1e-8)
            assert info.action == tuple(int(a) for a in action)
            prior = pymdp_jit.update_empirical_prior(agent, jnp.array([action]), qs)
            for f in range(3):  # the loop's next prior is pymdp's empirical prior
                np.testing.assert_allclose(state.prior[f], np.asarray(prior[f])[0], rtol=0, atol=1e-8)
            s_prev = list(s)
            s = [int(rng.choice(3, p=B[0][:, s_prev[0], int(action[0])])),
                 int(rng.choice(2, p=B[1][:, s_prev[0], s_prev[1], int(action[1])])),
                 int(rng.choice(2, p=B[2][:, s_prev[2], s_prev[1], int(action[2])]))]


def test_to_pymdp_sends_the_dependencies():
    pytest.importorskip("jax")
    pytest.importorskip("pymdp")
    from cogmap.inference import to_pymdp

    m, B = _model()
    agent = to_pymdp(m)
    assert [list(d) for d in agent.B_dependencies] == [[0], [0, 1], [2, 1]]
    np.testing.assert_allclose(np.asarray(agent.B[1])[0], B["b"], atol=1e-6)


# -- planning ---------------------------------------------------------------------------------
def test_policy_rollout_predicts_with_the_dependencies():
    from cogmap.planning import efe
    from cogmap.planning.arrays import from_model
    from cogmap.planning.arrays import prepare as prepare_planning
    from cogmap.planning.context import DenseStep

    m, _ = _model(8, pB=True)
    arrays = from_model(m)
    assert arrays.B_deps == DEPS
    prep = prepare_planning(arrays, local=False)
    rng = np.random.default_rng(9)
    qs = [_rnd(rng, 3), _rnd(rng, 2), _rnd(rng, 2)]
    acts = np.array(list(itertools.product(range(2), range(2), range(1))))
    ctx = DenseStep(prep, [np.broadcast_to(q, (len(acts), q.size)) for q in qs], acts)
    for k, u in enumerate(acts):
        pred = predict_factorised(m, qs, u)
        for f in range(3):
            np.testing.assert_allclose(ctx.qs[f][k], pred[f], rtol=0, atol=1e-14)
    # information gain about B of a factor with dependencies: E over the predicted joint of
    # (next state, previous states of its dependencies) of the novelty weights
    w = efe.novelty_weights(m.live_pB(1))
    for k, u in enumerate(acts):
        direct = np.einsum("nab,n,a,b->", w[..., u[1]], ctx.qs[1][k], qs[0], qs[1])
        assert ctx.b_novelty[1][k] == pytest.approx(direct, abs=1e-14)


def test_mcts_and_sparse_planning_refuse():
    from cogmap.genmodel.spec import SparseB
    from cogmap.planning import decide, efe, evaluate_policies

    m, _ = _model()
    with pytest.raises(ValueError, match="mcts does not support transitions that depend on several factors"):
        decide(m, [m.live_D(f) for f in range(3)], rng=0)
    # a sparse factor beside a factor with dependencies: inference works, planning refuses
    rng = np.random.default_rng(1)
    succ = np.repeat(np.arange(3)[:, None, None], 1, axis=1)
    spec = ModelSpec([Factor("x", 3, 1), Factor("y", 2, 1), Factor("z", 2, 1, depends_on=("z", "y"))],
                     [Modality("o", 2, ("z",))], A={"o": _rnd(rng, 2, 2)},
                     B={"x": SparseB(succ, np.ones((3, 1, 1))), "y": np.eye(2)[:, :, None], "z": _rnd(rng, 2, 2, 2, 1)})
    mixed = compile(spec)
    prior = [mixed.live_D(f) for f in range(3)]
    q, _ = fpi(mixed, prior, [[0], [1]], [(0, 0, 0)])
    ref, _ = exact(mixed, prior, [[0], [1]], [(0, 0, 0)])
    np.testing.assert_allclose(q[0], ref[0], atol=1e-12)
    with pytest.raises(ValueError, match="supported on dense models only"):
        evaluate_policies(mixed, prior, np.zeros((1, 1, 3), dtype=int), efe.pymdp_like())

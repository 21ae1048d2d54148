"""The JAX backend against the numpy reference: every scheme, the EFE terms and whole episodes, to 1e-10."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from inference_helpers import random_model, random_sequence

from cogmap import inference, jax_agent, loop
from cogmap.genmodel import Factor, Modality, ModelSpec, SpecError, compile
from cogmap.genmodel.demo_models import corridor, tmaze
from cogmap.genmodel.jax_model import to_jax
from cogmap.inference import jax_schemes as js
from cogmap.planning import efe
from cogmap.planning import jax_efe as je
from cogmap.planning.policies import enumerate_policies, evaluate_policies

SCHEMES = ("exact", "fpi", "vmp", "vmp_pymdp", "mmp", "filter")
TOL = 1e-10


@pytest.fixture(autouse=True)
def x64():
    with jax.enable_x64(True):
        yield


def _tmaze():
    m = tmaze()
    m.C[1][:3] = [0.0, 3.0, -6.0]
    return m


def _grid():
    """The numpy grid world's 2 x 2 rooms as a model: noisy colours, slightly slippery moves."""
    from cogmap.envs.gridworld import GridWorld, rooms_map

    world = GridWorld(rooms_map(2, 2, 3), n_colors=4, seed=1)
    A, B = world.A(), world.B()
    n = A.shape[1]
    moves = 0.9 * B[:, :, :4] + 0.1 * np.eye(n)[:, :, None]
    B = np.concatenate([moves, B[:, :, 4:]], axis=2)
    C = np.zeros(A.shape[0])
    C[2] = 2.0
    return compile(ModelSpec([Factor("cell", n, num_controls=5, stay=4)], [Modality("colour", A.shape[0], ("cell",))],
                             A={"colour": 0.85 * A + 0.15 / A.shape[0]}, B={"cell": B}, C={"colour": C}))


MODELS = {
    "random-1f": lambda: random_model(3, sizes=(5,), modalities=((0,), (0,))),
    "random-2f": lambda: random_model(4, sizes=(3, 4), modalities=((0,), (0, 1), (1,))),
    "tmaze": _tmaze,
    "grid": _grid,
}


MULTI_FACTOR = ("random-2f", "tmaze")
#: every (model, scheme) pair that applies (filter is a single-factor scheme)
CASES = [(n, s) for n in MODELS for s in SCHEMES if not (s == "filter" and n in MULTI_FACTOR)]


def _evidence(layout, arrays, obs):
    return js.evidence(layout, arrays, tuple(jnp.asarray(v) for v in js.one_hot_observation(layout, obs)))


def _stacked(layout, arrays, seq):
    evs = [_evidence(layout, arrays, o) for o in seq]
    return js.Evidence(tuple(jnp.stack([e.lik[m] for e in evs]) for m in range(layout.num_modalities)),
                       jnp.stack([e.present for e in evs]))


@pytest.mark.parametrize(("name", "scheme"), CASES)
def test_one_step_schemes_match_numpy(name, scheme):
    model = MODELS[name]()
    layout, arrays = to_jax(model)
    obs, _ = random_sequence(model, 3, seed=7, missing=0.2)
    rng = np.random.default_rng(0)
    for o in obs:
        prior = [rng.dirichlet(np.ones(n)) for n in model.num_states]
        q_np, info = inference.get(scheme)(model, prior, [o])
        q_j, F = js.SCHEMES[scheme](layout, arrays, tuple(jnp.asarray(p) for p in prior), _evidence(layout, arrays, o))
        for a, b in zip(q_j, q_np, strict=True):
            np.testing.assert_allclose(np.asarray(a), b, atol=TOL)
        assert abs(float(F) - info.free_energy) < TOL


@pytest.mark.parametrize("name", MULTI_FACTOR)
def test_fpi_stops_early_where_the_numpy_fpi_does(name):
    """With ``tol`` both stop after the same sweep: equal to each other, not to 16 sweeps (and a
    vmapped batch keeps each agent's own stop)."""
    model = MODELS[name]()
    layout, arrays = to_jax(model)
    obs, _ = random_sequence(model, 4, seed=3, missing=0.0)
    rng = np.random.default_rng(2)
    priors = [[rng.dirichlet(np.ones(n)) for n in model.num_states] for _ in obs]
    batch, early = [], []
    for o, prior in zip(obs, priors, strict=True):
        q_np, info = inference.get("fpi")(model, prior, [o], tol=1e-3)
        q_16, _ = inference.get("fpi")(model, prior, [o])
        ev = _evidence(layout, arrays, o)
        q_j, F = js.fpi(layout, arrays, tuple(jnp.asarray(p) for p in prior), ev, tol=1e-3)
        for a, b in zip(q_j, q_np, strict=True):
            np.testing.assert_allclose(np.asarray(a), b, atol=TOL)
        assert abs(float(F) - info.free_energy) < TOL
        early.append(max(np.abs(a - b).max() for a, b in zip(q_np, q_16, strict=True)) > 1e-8)
        batch.append((tuple(jnp.asarray(p) for p in prior), ev, q_np))
    assert any(early)  # some steps did stop before 16 sweeps
    stack = jax.tree_util.tree_map(lambda *x: jnp.stack(x), *[(p, e) for p, e, _ in batch])
    q_b, _ = jax.vmap(lambda p, e: js.fpi(layout, arrays, p, e, tol=1e-3))(*stack)
    for i, (_, _, q_np) in enumerate(batch):
        for f, b in enumerate(q_np):
            np.testing.assert_allclose(np.asarray(q_b[f][i]), b, atol=TOL)


@pytest.mark.parametrize("name", MODELS)
@pytest.mark.parametrize(("kind", "options"), [("vmp", {}), ("vmp", {"tol": 1e-4}), ("vmp_pymdp", {}),
                                               ("vmp_pymdp", {"tau": 0.5}), ("mmp", {})])
def test_windows_over_whole_sequences_match_numpy(name, kind, options):
    model = MODELS[name]()
    layout, arrays = to_jax(model)
    obs, acts = random_sequence(model, 5, seed=11, missing=0.1)
    prior = [model.live_D(f) for f in range(len(model.factors))]
    _, info = inference.get(kind)(model, prior, obs, acts, **options)
    qs, terms = js.window(kind, layout, arrays, tuple(jnp.asarray(p) for p in prior), _stacked(layout, arrays, obs),
                          jnp.asarray(acts), **options)
    for t, step in enumerate(info.history):
        for f, q in enumerate(step):
            np.testing.assert_allclose(np.asarray(qs[f][t]), q, atol=TOL)
    assert abs(float(terms.sum()) - info.total_free_energy) < TOL
    assert abs(float(terms[-1]) - info.free_energy) < TOL


def test_padded_capacity_gives_the_live_results():
    model = random_model(5, sizes=(5, 3), modalities=((0,), (0, 1)), growable=True)
    layout, arrays = to_jax(model)
    assert layout.capacity[0] > model.num_states[0], "a growable model reserves room"
    obs, _ = random_sequence(model, 1, seed=2)
    prior = [model.live_D(f) for f in range(2)]
    padded = tuple(jnp.zeros(c).at[:n].set(p)
                   for c, n, p in zip(layout.capacity, model.num_states, prior, strict=True))
    for scheme in ("exact", "fpi", "vmp", "vmp_pymdp", "mmp"):
        q_np, info = inference.get(scheme)(model, prior, obs)
        q_j, F = js.SCHEMES[scheme](layout, arrays, padded, _evidence(layout, arrays, obs[0]))
        for f, n in enumerate(model.num_states):
            np.testing.assert_allclose(np.asarray(q_j[f][:n]), q_np[f], atol=TOL)
            assert np.all(np.asarray(q_j[f][n:]) == 0.0), "not-yet-live states keep exactly zero mass"
        assert abs(float(F) - info.free_energy) < TOL


def _counted_chain():
    n = 6
    B = np.zeros((n, n, 3))
    for s in range(n):
        B[s, s, 0] = 1.0
        B[min(s + 1, n - 1), s, 1] = 1.0
        B[max(s - 1, 0), s, 2] = 1.0
    moves = np.concatenate([B[:, :, :1], 0.9 * B[:, :, 1:] + 0.1 / n], axis=2)
    A = np.full((3, n), 0.1)
    A[np.arange(n) % 3, np.arange(n)] = 0.8
    return compile(ModelSpec([Factor("p", n, num_controls=3, stay=0)], [Modality("o", 3, ("p",))],
                             A={"o": A}, B={"p": moves}, pA={"o": 5 * A + 0.2}, pB={"p": 3 * B + 0.5},
                             C_states={"p": 2.0 * np.eye(n)[4]}))


@pytest.mark.parametrize("length", [1, 2, 3])
def test_policy_efe_matches_numpy_with_every_term(length):
    model = _counted_chain()
    layout, arrays = to_jax(model, goal_dist=je.goal_distances_of(model))
    objective = efe.objective([(efe.state_info_gain, 1.0), (efe.observation_preference, 0.5),
                               (efe.param_info_gain, 1.0), (efe.state_preference, 3.0), (efe.inductive, 2.0)])
    policies = enumerate_policies(model.num_controls, length)
    rng = np.random.default_rng(length)
    for _ in range(3):
        q = rng.dirichlet(np.ones(6))
        G = evaluate_policies(model, [q], policies, objective)
        Gj = je.policy_efe(layout, arrays, je.prepare(arrays), je.weights_of(objective), (jnp.asarray(q),),
                           jnp.asarray(policies))
        np.testing.assert_allclose(np.asarray(Gj), G, atol=TOL)


def _episode(make, backend, scheme, steps=6, **kw):
    """Run the loop on ``make()`` with observations drawn from another copy of the model (seeded;
    the numpy loop learns its model in place, the world must not change with it)."""
    state = loop.init(make(), scheme=scheme, sample=False, backend=backend, **kw)
    model = make()
    rng = np.random.default_rng(5)
    true = [int(rng.choice(n, p=model.live_D(f))) for f, n in enumerate(model.num_states)]
    out = []
    for _ in range(steps):
        obs = []
        for m, deps in enumerate(model.A_deps):
            p = model.live_A(m)[(slice(None),) + tuple(true[f] for f in deps)]
            obs.append(int(rng.choice(p.size, p=p / p.sum())))
        state, info = loop.step(state, obs)
        out.append(info)
        true = [int(np.argmax(model.live_B(f)[:, true[f], info.action[f]])) for f in range(len(true))]
    return out


@pytest.mark.parametrize(("name", "scheme"), CASES)
def test_whole_episodes_agree_between_backends(name, scheme):
    ref = _episode(MODELS[name], "numpy", scheme, policy_len=2)
    got = _episode(MODELS[name], "jax", scheme, policy_len=2)
    for a, b in zip(ref, got, strict=True):
        assert a.action == b.action
        for qa, qb in zip(a.qs, b.qs, strict=True):
            np.testing.assert_allclose(qb, qa, atol=TOL)
        np.testing.assert_allclose(b.G, a.G, atol=TOL)
        np.testing.assert_allclose(b.q_pi, a.q_pi, atol=TOL)
        np.testing.assert_allclose(b.action_probs, a.action_probs, atol=TOL)
        assert abs(a.free_energy - b.free_energy) < TOL


def test_learning_episodes_agree_between_backends():
    def make():
        base = corridor(np.random.default_rng(0), n=4)
        A, B = base.live_A(0), base.live_B(0)
        return compile(ModelSpec([Factor("s", 4, num_controls=3)], [Modality("o", base.num_obs[0], ("s",))],
                                 A={"o": A}, B={"s": B}, pA={"o": 2 * A + 0.1}, pB={"s": 2 * B + 0.1}))

    kw = dict(learn_A=True, learn_B=True, lr_A=0.7, lr_B=1.3, objective="pymdp")
    ref = _episode(make, "numpy", "fpi", steps=8, **kw)
    got = _episode(make, "jax", "fpi", steps=8, **kw)
    for a, b in zip(ref, got, strict=True):
        assert a.action == b.action
        np.testing.assert_allclose(b.qs[0], a.qs[0], atol=TOL)
        np.testing.assert_allclose(b.G, a.G, atol=TOL)


def test_a_batch_of_agents_in_one_call_equals_each_agent_alone():
    model = _tmaze()
    agent = jax_agent.build(model, sample=True)
    keys = jax.random.split(jax.random.key(3), 8)
    rng = np.random.default_rng(0)
    obs = [tuple(jnp.asarray(np.eye(n)[rng.integers(n, size=8)]) for n in model.num_obs) for _ in range(3)]
    states = jax.vmap(agent.init)(keys)
    step = jax.jit(jax.vmap(agent.step))
    singles = [agent.init(k) for k in keys]
    for o in obs:
        states, info = step(states, o)
        for i in range(8):
            singles[i], one = jax_agent.jitted_step(agent.config, singles[i], tuple(x[i] for x in o), None)
            np.testing.assert_allclose(np.asarray(info.q_pi[i]), np.asarray(one.q_pi), atol=1e-12)
            assert np.array_equal(np.asarray(info.action[i]), np.asarray(one.action))
    shared = jax_agent.population(agent, keys)
    axes = (jax_agent.SHARED, 0)
    s2, info2 = jax.jit(jax.vmap(agent.step, in_axes=axes, out_axes=axes))(shared, obs[0])
    first = jax.vmap(agent.init)(keys)
    _, info1 = step(first, obs[0])
    np.testing.assert_allclose(np.asarray(info2.G), np.asarray(info1.G), atol=1e-12)


def test_a_given_action_replaces_the_agents_choice_on_both_backends():
    for backend in ("numpy", "jax"):
        state = loop.init(_tmaze(), sample=False, backend=backend, policy_len=1)
        state, info = loop.step(state, [0, 0, 0])
        own = info.action
        forced = (3, 0) if own != (3, 0) else (1, 0)
        state, info = loop.step(state, [0, 0, 0], action=forced)
        assert info.action == forced
        assert info.action_probs.shape == (4, 1)
        assert abs(info.action_probs.sum() - 1.0) < 1e-12
        np.testing.assert_allclose(info.action_probs[:, 0], info.q_pi, atol=1e-12)  # one-step policies
        with pytest.raises(ValueError, match="one integer control per factor"):
            loop.step(state, [0, 0, 0], action=(7, 0))


def test_bad_inputs_are_refused():
    from inference_helpers import pose_model

    with pytest.raises(SpecError, match="sparse"):
        to_jax(pose_model(5, 0))
    with pytest.raises(ValueError, match="unknown scheme"):
        jax_agent.build(_tmaze(), scheme="particle")
    with pytest.raises(ValueError, match="single-factor"):
        jax_agent.build(_tmaze(), scheme="filter")
    with pytest.raises(ValueError, match="no EFE term 'collision'"):
        jax_agent.build(_tmaze(), objective=efe.exploration())
    with pytest.raises(ValueError, match="tol must be a positive number or None, got -1"):
        jax_agent.build(_tmaze(), tol=-1)
    with pytest.raises(ValueError, match="tol is an option of fpi and vmp, not of 'vmp_pymdp'"):
        jax_agent.build(_tmaze(), scheme="vmp_pymdp", tol=1e-6)
    with pytest.raises(ValueError, match=r"tau is an option of vmp_pymdp and mmp, not of 'vmp' \(its coordinate"):
        jax_agent.build(_tmaze(), scheme="vmp", tau=0.5)
    with pytest.raises(ValueError, match="tau is an option of vmp_pymdp and mmp, not of 'fpi'"):
        jax_agent.build(_tmaze(), tau=0.5)
    with pytest.raises(ValueError, match="tau is an option of vmp_pymdp and mmp, not of 'vmp'"):
        js.window("vmp", *to_jax(_tmaze()), (), None, None, tau=1.0)
    with pytest.raises(ValueError, match="tol is an option of vmp, not of 'mmp'"):
        js.window("mmp", *to_jax(_tmaze()), (), None, None, tol=1e-3)
    with pytest.raises(ValueError, match="enumeration only"):
        loop.init(_tmaze(), planner="mcts", backend="jax")
    with pytest.raises(ValueError, match="unknown backend"):
        loop.init(_tmaze(), backend="torch")
    with pytest.raises(ValueError, match="agents that learn"):
        jax_agent.population(jax_agent.build(_counted_chain(), learn_A=True), jax.random.split(jax.random.key(0), 2))

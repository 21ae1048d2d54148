"""EFE terms: agreement with pymdp 1.0, sparse/dense agreement, composition, collision."""

from __future__ import annotations

import numpy as np
import pytest
from planning_builders import chain, graph_model, random_dense

from cogmap.planning import efe
from cogmap.planning.arrays import prepare
from cogmap.planning.context import DenseStep, LocalStep
from cogmap.planning.policies import (
    enumerate_policies,
    evaluate_policies,
    infer_policies,
    policy_posterior,
    select,
)

jax = pytest.importorskip("jax")
pytest.importorskip("pymdp")


def _pymdp_neg_efe(raw, qs, policies, use_param_info_gain):
    import jax.numpy as jnp
    from pymdp import control

    jax.config.update("jax_enable_x64", True)
    j = lambda xs: None if xs is None else [jnp.asarray(x) for x in xs]  # noqa: E731
    F = len(raw["B"])
    _, neg = control.update_posterior_policies(
        jnp.asarray(policies),
        j(qs),
        j(raw["A"]),
        j(raw["B"]),
        j(raw["C"]),
        jnp.ones(len(policies)) / len(policies),
        j(raw["pA"]),
        j(raw["pB"]),
        raw["A_deps"],
        [[f] for f in range(F)],
        gamma=1.0,
        use_utility=True,
        use_states_info_gain=True,
        use_param_info_gain=use_param_info_gain,
    )
    return np.asarray(neg)


CASES = [
    dict(num_states=(4,), num_controls=(3,), num_obs=(5,), length=3),
    dict(num_states=(6,), num_controls=(2,), num_obs=(3, 4), length=2),
    dict(num_states=(3, 4), num_controls=(2, 3), num_obs=(5, 3), length=2),
    dict(num_states=(3, 2), num_controls=(3, 1), num_obs=(4, 2), length=2, A_deps=[[0], [0, 1]]),
]


@pytest.mark.parametrize("case", CASES)
@pytest.mark.parametrize("param", [False, True])
@pytest.mark.parametrize("seed", [0, 1])
def test_policy_efe_matches_pymdp(case, param, seed):
    rng = np.random.default_rng(seed)
    case = dict(case)
    length = case.pop("length")
    arrays, raw = random_dense(rng, **case)
    qs = [rng.dirichlet(np.ones(n)) for n in arrays.num_states]
    policies = enumerate_policies(arrays.num_controls, length)
    G = evaluate_policies(arrays, qs, policies, efe.pymdp_like(use_param_info_gain=param))
    neg = _pymdp_neg_efe(raw, qs, policies, param)
    np.testing.assert_allclose(G, -neg, atol=1e-4, rtol=0)


def test_enumeration_matches_pymdp_construct_policies():
    from pymdp.control import construct_policies

    ours = enumerate_policies([3, 1, 2], 2)
    ref = np.asarray(construct_policies([4, 2, 3], [3, 1, 2], policy_len=2))
    np.testing.assert_array_equal(ours, ref)


def test_term_decomposition_sums_to_pymdp_parts():
    rng = np.random.default_rng(3)
    arrays, _ = random_dense(rng, (5,), (3,), (4,))
    prep = prepare(arrays, local=False)
    q = [np.tile(rng.dirichlet(np.ones(5)), (3, 1))]
    ctx = DenseStep(prep, q, np.arange(3)[:, None])
    ig = efe.state_info_gain(ctx)
    assert np.all(ig >= -1e-12)  # mutual information is non-negative
    assert np.all(efe.param_info_gain(ctx) >= 0)
    obj = efe.objective([(efe.state_info_gain, 2.0), ("observation_preference", 0.5)])
    np.testing.assert_allclose(obj(ctx), -(2.0 * ig + 0.5 * efe.observation_preference(ctx)))
    parts = obj.breakdown(ctx)
    np.testing.assert_allclose(sum(parts.values()), obj(ctx))
    assert obj.names == ("state_info_gain", "observation_preference")


def test_objective_rejects_unknown_terms():
    with pytest.raises(KeyError, match="unknown EFE term"):
        efe.objective([("curiosity", 1.0)])
    with pytest.raises(TypeError):
        efe.objective([(3, 1.0)])


def _both_contexts(arrays, s, acts, collision=None):
    """The same step through the sparse local path and the densified path."""
    local = prepare(arrays, local=True)
    dense = prepare(arrays, local=False)
    q0 = np.zeros(arrays.num_states[0])
    q0[s] = 1.0
    K = len(acts)
    lctx = LocalStep(local, (s,), (1.0,), acts, 0, collision)
    dctx = DenseStep(dense, [np.tile(q0, (K, 1))], np.asarray(acts)[:, None], 0, collision)
    return lctx, dctx


@pytest.mark.parametrize("term", sorted(efe.ALL_TERMS))
def test_local_sparse_path_matches_dense(term):
    G, poses = chain(8)
    rng = np.random.default_rng(0)
    visited = rng.random(8) < 0.5
    C_states = np.zeros(8)
    C_states[6] = 2.0
    arrays = graph_model(
        G, poses, visited=visited, C_states=[C_states], target_pose=np.array([6.0, 0.5]),
        goal_states=np.array([6]), inductive_depth=4, num_obs=5,
    )
    arrays = type(arrays)(**{**arrays.__dict__, "C": [rng.normal(size=5)]})
    acts = np.array([0, 6, 12, 3])
    coll = np.array([0.0, 1.0, 0.0, 0.5])
    for s in (2, 3, 5):
        lctx, dctx = _both_contexts(arrays, s, acts, coll)
        np.testing.assert_allclose(efe.ALL_TERMS[term](lctx), efe.ALL_TERMS[term](dctx), atol=1e-10)


def test_local_path_with_uncertain_prior_matches_dense():
    G, poses = chain(8)
    arrays = graph_model(G, poses, visited=np.arange(8) % 2 == 0, num_obs=4)
    prior = np.zeros(8)
    prior[[2, 3, 4]] = [0.6, 0.3, 0.1]
    acts = np.array([0, 6, 12])
    lctx = LocalStep(prepare(arrays, local=True), np.array([2, 3, 4]), prior[[2, 3, 4]], acts)
    dctx = DenseStep(prepare(arrays, local=False), [np.tile(prior, (3, 1))], acts[:, None])
    obj = efe.full()
    np.testing.assert_allclose(obj(lctx), obj(dctx), atol=1e-10)


def test_position_preference_is_gaussian_log_preference():
    G, poses = chain(5)
    arrays = graph_model(G, poses, target_pose=np.array([4.0, 0.0]), pose_sigma=2.0)
    lctx = LocalStep(prepare(arrays), (2,), (1.0,), np.array([0, 6, 12]))
    val = efe.position_preference(lctx)
    q = lctx.qs[0]
    expect = q @ (-0.5 * ((poses[lctx.U] - [4.0, 0.0]) ** 2).sum(1) / 4.0)
    np.testing.assert_allclose(val, expect)
    assert val[0] > val[2] > val[1]  # east (toward the target) > stay > west


def test_collision_term_excludes_flagged_direction_in_enumeration():
    # a symmetric model: every control has the same transitions, so only collision differs
    rng = np.random.default_rng(0)
    arrays, _ = random_dense(rng, (4,), (1,), (3,))
    B = np.repeat(arrays.B[0].prob, 4, axis=2)
    arrays = type(arrays)(**{**arrays.__dict__, "B": [B], "num_controls": (4,), "pB": None})
    qs = [np.ones(4) / 4]
    for blocked in range(4):
        flags = np.zeros(4, dtype=bool)
        flags[blocked] = True
        flags[(blocked + 2) % 4] = True
        for obj in (efe.exploration(), efe.goal(), efe.full()):
            a, q, G, pol = infer_policies(arrays, qs, obj, length=2, obstacles=flags)
            assert not flags[a[0]]
            assert q[pol[:, 0, 0] == blocked].sum() < q[pol[:, 0, 0] != blocked].sum()
            for seed in range(5):  # sampled selection avoids it too (with high precision)
                i = select(policy_posterior(G, 64.0), np.random.default_rng(seed))
                assert not flags[pol[i, 0, 0]]


def test_softmax_selection_is_seeded():
    G = np.array([1.0, 0.5, 0.7])
    q = policy_posterior(G, gamma=2.0)
    np.testing.assert_allclose(q, np.exp(-2 * G) / np.exp(-2 * G).sum())
    a = [select(q, np.random.default_rng(7)) for _ in range(3)]
    assert len(set(a)) == 1
    assert select(q) == 1

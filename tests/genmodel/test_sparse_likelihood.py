"""SparseLikelihood against a dense reference kept by hand, through growth, learning, inference,
planning and persistence."""

from __future__ import annotations

import json

import numpy as np
import pytest

from cogmap.genmodel import Factor, Modality, ModelSpec, SparseA, SparseB, SparseLikelihood, SpecError, compile
from cogmap.genmodel.io import ModelFileError, load, save
from cogmap.inference import bayes_filter
from cogmap.inference.learning import learn_observation
from cogmap.planning import efe
from cogmap.planning.arrays import PlanningArrays, prepare
from cogmap.planning.context import DenseStep, LocalStep
from cogmap.planning.efe import entropy, novelty_weights


class DenseReference:
    """The rule of the module docstring, kept densely: prior mass spread over live outcomes."""

    def __init__(self, prior, num_obs):
        self.prior = list(prior)
        self.learned = np.zeros((num_obs, len(prior)))

    def add_state(self, c):
        self.prior.append(c)
        self.learned = np.hstack([self.learned, np.zeros((self.learned.shape[0], 1))])

    def add_observation(self):
        self.learned = np.vstack([self.learned, np.zeros((1, self.learned.shape[1]))])

    def counts(self):
        return np.asarray(self.prior)[None, :] / self.learned.shape[0] + self.learned

    def A(self):
        c = self.counts()
        return c / c.sum(axis=0)


def random_history(seed, steps=120):
    rng = np.random.default_rng(seed)
    L = SparseLikelihood(1, 1, capacity=2, slots=2)
    L.prior[0] = 0.3
    ref = DenseReference([0.3], 1)
    for _ in range(steps):
        r = rng.random()
        if r < 0.25:
            c = float(rng.uniform(0.05, 2.0))
            L.add_state(0, c / L.num_obs)
            ref.add_state(c)
        elif r < 0.45:
            L.add_observation()
            ref.add_observation()
        else:
            o = int(rng.integers(L.num_obs))
            q = rng.dirichlet(np.full(L.num_states, 0.3))
            q[q < 1e-3] = 0.0  # sparse beliefs, as the agent's
            q /= q.sum()
            lr = float(rng.uniform(0.5, 4.0))
            L.learn(o, [q], lr)
            ref.learned[o] += lr * q
    return L, ref, rng


@pytest.mark.parametrize("seed", range(4))
def test_entries_rows_columns_match_the_dense_rule(seed):
    L, ref, rng = random_history(seed)
    np.testing.assert_allclose(L.counts_dense(), ref.counts(), atol=1e-12)
    A = ref.A()
    np.testing.assert_allclose(L.to_dense(), A, atol=1e-12)
    np.testing.assert_allclose(A.sum(axis=0), 1.0, atol=1e-12)
    for o in range(L.num_obs):
        np.testing.assert_allclose(L.row(o), A[o], atol=1e-12)
        np.testing.assert_allclose(L.counts_row(o), ref.counts()[o], atol=1e-12)
    for s in range(L.num_states):
        np.testing.assert_allclose(L.column(s), A[:, s], atol=1e-12)
        np.testing.assert_array_equal(L.outcomes_above(s, 0.3), np.flatnonzero(A[:, s] >= 0.3))
    p = rng.dirichlet(np.ones(L.num_obs))
    np.testing.assert_allclose(L.expected_row(p), p @ A, atol=1e-12)
    np.testing.assert_array_equal(L.taught(1.0), ref.counts().max(axis=0) > 1.0)
    learned = ref.learned.max(axis=0) > 0
    np.testing.assert_array_equal(L.most_likely()[learned], ref.learned.argmax(axis=0)[learned])


@pytest.mark.parametrize("seed", range(3))
def test_column_statistics_match_dense_entropy_and_novelty(seed):
    L, ref, _ = random_history(seed)
    states = np.arange(L.num_states)
    H, w_bg, w_slots = L.column_stats(states)
    np.testing.assert_allclose(H, entropy(ref.A(), axis=0), atol=1e-12)
    W = novelty_weights(ref.counts())
    for s in states:
        learned = L.obs[s][L.obs[s] >= 0]
        np.testing.assert_allclose(w_slots[s][L.obs[s] >= 0], W[learned, s], atol=1e-12)
        rest = np.setdiff1d(np.arange(L.num_obs), learned)
        np.testing.assert_allclose(W[rest, s], w_bg[s], atol=1e-12)


def test_growth_reallocates_logarithmically_and_keeps_learned_counts():
    L = SparseLikelihood(1, 1, capacity=1)
    L.prior[0] = 1.0
    L.learn(0, [np.array([1.0])], 3.0)
    for _ in range(1000):
        L.add_state(0, 1.0 / L.num_obs)
        L.add_observation()
    assert L.reallocations <= int(np.ceil(np.log2(1001)))
    assert L.counts_row(0)[0] == pytest.approx(3.0 + 1.0 / 1001)
    # memory is per state and slot (capacity at most twice the states), not per (outcome, state) pair
    assert L.capacity < 2 * 1001
    assert L.nbytes == L.capacity * 8 * (2 + 2 * L.slots)


def _sparse_arrays(seed):
    """A single-factor map with a sparse likelihood, and the same map with its dense arrays."""
    from cogmap.planning.testing import graph_arrays, lattice_graph

    rng = np.random.default_rng(seed)
    G, poses = lattice_graph(30, rng)
    base = graph_arrays(G, poses, visited=rng.random(30) < 0.5, num_obs=12, rng=rng)
    n = base.num_states[0]
    L = SparseLikelihood(12, 0, capacity=n)
    for _ in range(n):
        L.add_state(0, float(rng.uniform(0.1, 1.0)) / L.num_obs)
    for _ in range(40):
        q = np.zeros(n)
        idx = rng.choice(n, size=3, replace=False)
        q[idx] = rng.dirichlet(np.ones(3))
        L.learn(int(rng.integers(12)), [q], float(rng.uniform(1, 5)))
    C = [rng.normal(size=12)]
    sparse = PlanningArrays(**{**base.__dict__, "A": [L], "pA": [None], "C": C})
    dense = PlanningArrays(**{**base.__dict__, "A": [L.to_dense()], "pA": [L.counts_dense()], "C": C})
    return sparse, dense


@pytest.mark.parametrize("term", sorted(efe.ALL_TERMS))
def test_planning_terms_with_a_sparse_likelihood_match_the_dense_arrays(term):
    sparse, dense = _sparse_arrays(1)
    acts = np.array([0, 3, 6, 9, 12])
    coll = np.array([0.0, 1.0, 0.0, 0.5, 0.0])
    for prior_idx, prior_p in (((4,), (1.0,)), (np.array([2, 5, 7]), np.array([0.5, 0.3, 0.2]))):
        s_ctx = LocalStep(prepare(sparse, local=True), prior_idx, prior_p, acts, 0, coll)
        d_ctx = LocalStep(prepare(dense, local=True), prior_idx, prior_p, acts, 0, coll)
        np.testing.assert_allclose(efe.ALL_TERMS[term](s_ctx), efe.ALL_TERMS[term](d_ctx), atol=1e-10)
    # and against the fully dense context
    q0 = np.zeros(dense.num_states[0])
    q0[4] = 1.0
    full = DenseStep(prepare(dense, local=False), [np.tile(q0, (acts.size, 1))], acts[:, None], 0, coll)
    s_ctx = LocalStep(prepare(sparse, local=True), (4,), (1.0,), acts, 0, coll)
    np.testing.assert_allclose(efe.ALL_TERMS[term](s_ctx), efe.ALL_TERMS[term](full), atol=1e-10)


def _spec(n=3, u=2, learned=((0, 1, 2.0), (2, 2, 1.5))):
    succ = np.broadcast_to(np.arange(n)[:, None, None], (n, u, 1)).copy()
    prob = np.ones((n, u, 1))
    o, s, c = (np.array(x) for x in zip(*learned, strict=True)) if learned else ([], [], [])
    return ModelSpec(
        factors=[Factor("place", n, num_controls=u, growable=True)],
        modalities=[Modality("view", 4, ("place",), growable=True)],
        A={"view": SparseA(np.full(n, 0.4), o, s, c)},
        B={"place": SparseB(succ, prob, counts=np.full((n, u, 1), 2.0))},
    )


def test_compiled_sparse_model_filters_and_learns_like_its_dense_twin():
    model = compile(_spec())
    dense_A = model.live_A(0)
    twin = compile(ModelSpec(
        factors=[Factor("place", 3, num_controls=2, growable=True)],
        modalities=[Modality("view", 4, ("place",), growable=True)],
        A={"view": dense_A}, pA={"view": model.live_pA(0)},
        B={"place": model.live_B(0)}, pB={"place": model.live_pB(0)},
    ))
    prior = [np.array([0.2, 0.5, 0.3])]
    for o in range(4):
        q_s, _ = bayes_filter(model, prior, [{"view": o}])
        q_d, _ = bayes_filter(twin, prior, [{"view": o}])
        np.testing.assert_allclose(q_s[0], q_d[0], atol=1e-12)
    learn_observation(model, 0, 3, [np.array([0.0, 1.0, 0.0])], lr=2.0)
    learn_observation(twin, 0, 3, [np.array([0.0, 1.0, 0.0])], lr=2.0)
    np.testing.assert_allclose(model.live_A(0), twin.live_A(0), atol=1e-12)
    np.testing.assert_allclose(model.live_pB(0), twin.live_pB(0), atol=1e-12)


def test_model_growth_with_a_sparse_likelihood_keeps_columns_normalised():
    model = compile(_spec())
    with pytest.raises(SpecError, match="takes no count"):
        model.add_observation(0, count=0.5)
    for _ in range(100):
        model.add_observation(0)
        model.add_state(0, obs_count=0.01)
    A = model.live_A(0)
    assert A.shape == (104, 103)
    np.testing.assert_allclose(A.sum(axis=0), 1.0, atol=1e-12)
    assert model.A[0].total([102])[0] == pytest.approx(0.01 * 104)  # obs_count x live outcomes at add time


@pytest.mark.parametrize(
    "change, message",
    [
        (dict(prior=np.ones(2)), "expected \\(3,\\)"),
        (dict(outcomes=np.array([9]), states=np.array([0]), counts=np.array([1.0])), "out of range"),
        (dict(outcomes=np.array([0]), states=np.array([0]), counts=np.array([-1.0])), "non-negative"),
        (dict(outcomes=np.array([0, 1]), states=np.array([0]), counts=np.array([1.0])), "same length"),
        (dict(prior=np.array([0.0, 1.0, 1.0])), "no positive count"),
    ],
)
def test_sparse_A_spec_errors_name_the_problem(change, message):
    spec = _spec()
    raw = spec.A["view"]
    spec.A["view"] = SparseA(**{**raw.__dict__, **change})
    with pytest.raises(SpecError, match=message):
        compile(spec)


def test_sparse_A_refuses_double_counts_and_several_factors():
    spec = _spec()
    spec.pA["view"] = np.ones((4, 3))
    with pytest.raises(SpecError, match="give them once"):
        compile(spec)
    spec = _spec()
    spec.factors.append(Factor("other", 2))
    spec.B["other"] = np.stack([np.eye(2)], axis=2)
    spec.modalities[0] = Modality("view", 4, ("place", "other"), growable=True)
    with pytest.raises(SpecError, match="exactly one factor"):
        compile(spec)


def test_sparse_model_round_trips_and_version_1_files_still_load(tmp_path):
    model = compile(_spec())
    learn_observation(model, 0, 1, [np.array([0.0, 0.0, 1.0])], lr=4.0)
    model.add_observation(0)
    save(model, tmp_path / "m")
    back = load(tmp_path / "m")
    assert back.is_sparse_A(0)
    np.testing.assert_allclose(back.live_A(0), model.live_A(0), atol=1e-15)
    np.testing.assert_allclose(back.live_pB(0), model.live_pB(0), atol=1e-15)
    # a version-1 file (dense arrays only) still loads
    dense = compile(ModelSpec(factors=[Factor("s", 2)], modalities=[Modality("o", 2, ("s",))],
                              A={"o": np.eye(2)}, B={"s": np.eye(2)[:, :, None]}))
    save(dense, tmp_path / "d")
    meta = json.loads((tmp_path / "d.json").read_text())
    meta["version"] = 1
    del meta["sparse_A"]
    (tmp_path / "d.json").write_text(json.dumps(meta))
    np.testing.assert_allclose(load(tmp_path / "d").live_A(0), np.eye(2))
    meta["version"] = 7
    (tmp_path / "d.json").write_text(json.dumps(meta))
    with pytest.raises(ModelFileError, match="version 7 is not supported"):
        load(tmp_path / "d")

"""Sophisticated inference: the recursion over actions and outcomes against a brute-force one, its
one-step limit, the T-maze (where branching on what the cue will say matters), the loop, bad inputs."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from cogmap import loop
from cogmap.envs.jax_worlds import grid_model, tmaze_model
from cogmap.planning import (
    PlanSettings,
    SophisticatedConfig,
    available_planners,
    efe,
    enumerate_policies,
    evaluate_policies,
    get_planner,
    sophisticated_efe,
)
from cogmap.planning.arrays import prepare
from cogmap.planning.efe import novelty_weights
from cogmap.planning.policies import infer_policies
from cogmap.planning.sophisticated import EXHAUSTIVE, PRUNED_LOG_WEIGHT, planner_with
from cogmap.planning.testing import graph_arrays

from .planning_builders import chain, random_dense

CENTRE, LEFT, RIGHT, CUE = range(4)


# -- an independent brute-force recursion: plain loops over every joint control and joint outcome ---------
class BruteForce:
    """Exact sophisticated EFE on the joint state space (Kronecker transitions, likelihoods over the joint)."""

    def __init__(self, raw, num_states, num_controls, num_obs, novelty):
        self.shape, self.controls, self.num_obs = tuple(num_states), tuple(num_controls), tuple(num_obs)
        self.states = list(itertools.product(*(range(n) for n in num_states)))
        N = len(self.states)
        self.A, self.WA = [], []
        for m, deps in enumerate(raw["A_deps"]):
            A_j = np.zeros((num_obs[m], N))
            W_j = np.zeros((num_obs[m], N))
            W = novelty_weights(raw["pA"][m]) if novelty else None
            for i, s in enumerate(self.states):
                col = (slice(None),) + tuple(s[f] for f in deps)
                A_j[:, i] = raw["A"][m][col]
                if novelty:
                    W_j[:, i] = W[col]
            self.A.append(A_j)
            self.WA.append(W_j)
        self.B = {}
        for u in itertools.product(*(range(c) for c in num_controls)):
            Bj = np.ones((1, 1))
            for f, B in enumerate(raw["B"]):
                Bj = np.kron(Bj, B[:, :, u[f]])
            self.B[u] = Bj
        self.WB = [novelty_weights(pB) for pB in raw["pB"]] if novelty else None
        self.C = raw["C"]
        self.novelty = novelty

    def marginal(self, q, f):
        return np.asarray(q).reshape(self.shape).sum(axis=tuple(g for g in range(len(self.shape)) if g != f))

    def one_step(self, q, u):
        nxt = self.B[u] @ q
        G = 0.0
        for m in range(len(self.A)):
            qo = self.A[m] @ nxt
            h_qo = -sum(p * np.log(p) for p in qo if p > 0)
            amb = sum(nxt[i] * -sum(p * np.log(p) for p in self.A[m][:, i] if p > 0) for i in range(len(q)))
            G -= h_qo - amb + qo @ self.C[m]
            if self.novelty:
                G -= sum(qo[o] * (self.WA[m][o] @ nxt) for o in range(len(qo)))
        if self.novelty:
            for f in range(len(self.shape)):
                G -= self.marginal(nxt, f) @ self.WB[f][:, :, u[f]] @ self.marginal(q, f)
        return G, nxt

    def G(self, q, depth, gamma):
        out = []
        for u in itertools.product(*(range(c) for c in self.controls)):
            g, nxt = self.one_step(q, u)
            if depth > 1:
                for o in itertools.product(*(range(n) for n in self.num_obs)):
                    lik = np.ones(len(q))
                    for m, om in enumerate(o):
                        lik = lik * self.A[m][om]
                    p = lik @ nxt
                    if p > 0:
                        Gc = self.G(lik * nxt / p, depth - 1, gamma)
                        w = np.exp(-gamma * (Gc - Gc.min()))
                        g += p * (w / w.sum()) @ Gc
            out.append(g)
        return np.array(out)


CASES = [  # num_states, num_controls, num_obs, A_deps, horizon
    ((3,), (2,), (3,), None, 3),
    ((3,), (4,), (2, 3), None, 2),
    ((2, 3), (2, 1), (3,), [(0, 1)], 2),
    ((2, 2), (2, 3), (2, 3), [(1,), (1, 0)], 2),
    ((2, 2), (3, 1), (2, 2), [(0,), (0, 1)], 3),
    ((2,), (2,), (2,), None, 1),
]


@pytest.mark.parametrize("novelty", [False, True])
@pytest.mark.parametrize("case", range(len(CASES)))
def test_exhaustive_search_equals_brute_force_recursion(case, novelty):
    num_states, num_controls, num_obs, deps, horizon = CASES[case]
    rng = np.random.default_rng(100 + case)
    arrays, raw = random_dense(rng, num_states, num_controls, num_obs, A_deps=deps)
    qs = [rng.dirichlet(np.ones(n)) for n in num_states]
    gamma = 2.0
    objective = efe.pymdp_like(use_param_info_gain=novelty)
    G, info = sophisticated_efe(arrays, qs, objective, horizon, gamma, EXHAUSTIVE)
    belief = qs[0]
    for q in qs[1:]:
        belief = np.kron(belief, q)
    expected = BruteForce(raw, num_states, num_controls, num_obs, novelty).G(belief, horizon, gamma)
    np.testing.assert_allclose(G, expected, rtol=0, atol=1e-10)
    assert info.expanded.all()


@pytest.mark.parametrize("seed", range(4))
def test_horizon_one_is_the_one_step_policy_evaluation(seed):
    rng = np.random.default_rng(seed)
    num_states, num_controls = [((4,), (3,)), ((2, 3), (2, 2)), ((3, 2), (4, 1)), ((5,), (2,))][seed]
    arrays, _ = random_dense(rng, num_states, num_controls, (3, 2), A_deps=[(0,), tuple(range(len(num_states)))])
    qs = [rng.dirichlet(np.ones(n)) for n in num_states]
    policies = enumerate_policies(num_controls, 1)
    for objective in (efe.pymdp_like(), efe.pymdp_like(use_param_info_gain=True)):
        G, info = sophisticated_efe(arrays, qs, objective, 1, 16.0)
        np.testing.assert_allclose(G, evaluate_policies(arrays, qs, policies, objective), rtol=0, atol=1e-12)
        np.testing.assert_allclose(info.G_one_step, G, rtol=0, atol=0)
        assert info.nodes == 1


def test_horizon_one_on_the_tmaze_and_a_sparse_model():
    model = tmaze_model()
    qs = [np.eye(4)[CENTRE], np.array([0.5, 0.5])]
    policies = enumerate_policies(model.num_controls, 1)
    np.testing.assert_allclose(sophisticated_efe(model, qs, efe.pymdp_like(), 1)[0],
                               evaluate_policies(model, qs, policies, efe.pymdp_like()), rtol=0, atol=1e-12)
    G_graph, poses = chain(6)
    arrays = graph_arrays(G_graph, poses)  # one sparse factor: densified for this planner
    q = [np.full(6, 1 / 6)]
    np.testing.assert_allclose(sophisticated_efe(arrays, q, efe.pymdp_like(), 1)[0],
                               evaluate_policies(arrays, q, enumerate_policies(arrays.num_controls, 1),
                                                 efe.pymdp_like()), rtol=0, atol=1e-12)
    assert np.all(np.isfinite(sophisticated_efe(arrays, q, efe.pymdp_like(), 2)[0]))


# -- the T-maze: the cue is worth visiting because the next step can depend on what it says ---------------
def _tmaze():
    return tmaze_model(), [np.eye(4)[CENTRE], np.array([0.5, 0.5])]


@pytest.mark.parametrize("config", [None, EXHAUSTIVE])
def test_tmaze_the_cue_pays_only_when_planning_on_what_it_will_say(config):
    """Utility only (no epistemic term). Rolling beliefs forward, the context stays 50/50 whatever the
    agent does, so an arm is a gamble with negative expected utility (0.5 (2.7 - 0.6) + 0.5 (0.3 - 5.4)
    = -1.5 at a reached arm) and the cue is worth exactly as much as staying at the centre (the moves
    are symmetric, the cue arm has no preference). Sophisticated inference conditions the second step on
    the cue's outcome: after it the right arm is a good bet (about 0.9 * 0.95 reward), so going to the
    cue first has clearly negative EFE and beats staying."""
    model, qs = _tmaze()
    utility = efe.pymdp_like(use_states_info_gain=False)
    _, _, G_enum, policies = infer_policies(model, qs, utility, length=2)
    first = policies[:, 0, 0]
    enum_best = np.array([G_enum[first == u].min() for u in range(4)])
    assert abs(enum_best[CUE] - enum_best[CENTRE]) < 1e-9  # enumeration: the cue is worth nothing
    assert enum_best[CUE] > 0 and enum_best[LEFT] > enum_best[CUE]

    G, _ = sophisticated_efe(model, qs, utility, 2, 16.0, config)
    assert int(np.argmin(G)) == CUE
    assert G[CUE] < -1.0 < G[CENTRE] - 1.0  # more than a nat better than staying, and negative
    assert G[CUE] < enum_best[CUE] - 1.0


def test_tmaze_sophisticated_values_the_cue_above_the_open_loop_plan():
    """With pymdp's objective both planners go to the cue first, but the sophisticated value of doing so
    adds the conditional choice of arm: lower than the best open-loop policy through the cue."""
    model, qs = _tmaze()
    obj = efe.pymdp_like()
    _, _, G_enum, policies = infer_policies(model, qs, obj, length=2)
    enum_cue = G_enum[policies[:, 0, 0] == CUE].min()
    for config in (None, EXHAUSTIVE):
        G, info = sophisticated_efe(model, qs, obj, 2, 16.0, config)
        assert int(np.argmin(G)) == CUE
        assert G[CUE] < enum_cue - 1.0
    G, info = sophisticated_efe(model, qs, obj, 2, 16.0)  # SPM's thresholds prune the arms and the centre
    assert info.expanded.tolist() == [False, False, False, True]
    np.testing.assert_allclose(G[~info.expanded], G[CUE] + PRUNED_LOG_WEIGHT / 16.0)


def test_pruning_keeps_the_choice_and_bounds_the_search_at_400_states():
    model = grid_model(side=20)
    n = model.num_states[0]
    G, info = sophisticated_efe(model, [np.eye(n)[n - 3]], efe.pymdp_like(), 4, 16.0)
    assert int(np.argmin(G)) == 1  # +x: two cells from the preferred corner
    assert info.nodes <= 1 + 5 + 25 + 125  # at most one outcome per expanded control here
    cfg = SophisticatedConfig(outcome_threshold=0.0, action_threshold=0.0, max_outcomes=2)
    G2, info2 = sophisticated_efe(model, [np.eye(n)[n - 3]], efe.pymdp_like(), 3, 16.0, cfg)
    assert int(np.argmin(G2)) == 1 and info2.expanded.all()


# -- the planner by name and in the loop ----------------------------------------------------------------
def test_the_planner_is_registered_and_returns_root_controls():
    assert "sophisticated" in available_planners()
    model, qs = _tmaze()
    plan = get_planner("sophisticated")(model, qs, efe.pymdp_like(), PlanSettings(policy_len=2, sample=False))
    assert plan.action == (CUE, 0)
    assert plan.policies.shape == (4, 1, 2) and plan.G.shape == (4,)
    np.testing.assert_allclose(plan.q_pi.sum(), 1.0)
    assert int(np.argmax(plan.q_pi)) == CUE
    rng = np.random.default_rng(0)
    sampled = get_planner("sophisticated")(model, qs, None, PlanSettings(policy_len=2, rng=rng, sample=True))
    assert sampled.action[1] == 0 and 0 <= sampled.action[0] < 4


def test_the_loop_reads_the_cue_then_goes_where_it_points():
    model = tmaze_model()
    state = loop.init(model, planner="sophisticated", policy_len=2, sample=False)
    state, info = loop.step(state, [CENTRE, 0, 0])
    assert info.action == (CUE, 0)
    assert info.action_probs.shape == (4, 1)
    np.testing.assert_allclose(info.action_probs.sum(), 1.0)
    assert int(np.argmax(info.action_probs[:, 0])) == CUE
    state, info = loop.step(state, [CUE, 0, 1])  # the cue says context 1: the reward is on the right
    assert info.qs[1][1] > 0.9
    assert info.action == (RIGHT, 0)


def test_planner_with_other_thresholds():
    model, qs = _tmaze()
    plan = planner_with(EXHAUSTIVE)(model, qs, efe.pymdp_like(), PlanSettings(policy_len=2, sample=False))
    np.testing.assert_allclose(plan.G, sophisticated_efe(model, qs, efe.pymdp_like(), 2, 16.0, EXHAUSTIVE)[0])
    assert plan.info.expanded.all()


# -- bad inputs --------------------------------------------------------------------------------------
def test_bad_inputs_are_refused_with_clear_messages():
    model, qs = _tmaze()
    obj = efe.pymdp_like()
    for h in (0, -1, 1.5, True):
        with pytest.raises(ValueError, match="horizon"):
            sophisticated_efe(model, qs, obj, h)
    with pytest.raises(ValueError, match="horizon"):
        get_planner("sophisticated")(model, qs, obj, PlanSettings(policy_len=0))
    for bad in (-0.1, 1.5, float("nan"), "1/16"):
        with pytest.raises(ValueError, match="outcome_threshold"):
            sophisticated_efe(model, qs, obj, 2, config=SophisticatedConfig(outcome_threshold=bad))
        with pytest.raises(ValueError, match="action_threshold"):
            sophisticated_efe(model, qs, obj, 2, config=SophisticatedConfig(action_threshold=bad))
    with pytest.raises(ValueError, match="max_outcomes"):
        sophisticated_efe(model, qs, obj, 2, config=SophisticatedConfig(max_outcomes=0))
    with pytest.raises(ValueError, match="max_outcomes"):
        planner_with(SophisticatedConfig(max_outcomes=2.5))
    with pytest.raises(ValueError, match="gamma"):
        sophisticated_efe(model, qs, obj, 2, gamma=0.0)
    with pytest.raises(ValueError, match="joint state space has 8 states.*max_states=4"):
        sophisticated_efe(model, qs, obj, 2, config=SophisticatedConfig(max_states=4))
    with pytest.raises(ValueError, match="beliefs for 1 factor"):
        sophisticated_efe(model, qs[:1], obj, 2)
    G_graph, poses = chain(6)
    local = prepare(graph_arrays(G_graph, poses))  # the sparse (local) path
    assert local.local
    with pytest.raises(ValueError, match="dense preparation"):
        sophisticated_efe(local, [np.full(6, 1 / 6)], obj, 2)

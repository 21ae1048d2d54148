"""MCTS over EFE: value-based selection, agreement with enumeration, goal finding, pruning."""

from __future__ import annotations

from dataclasses import replace

import networkx as nx
import numpy as np
import pytest
from planning_builders import corridor_rooms, graph_model, random_dense

from cogmap.planning import efe
from cogmap.planning.arrays import prepare
from cogmap.planning.mcts import MCTSConfig, allowed_actions, mcts, search, ucb_select
from cogmap.planning.policies import enumerate_policies, evaluate_policies
from cogmap.planning.testing import STAY


def test_ucb_selection_uses_values():
    # equal visits: only the values can decide; the best value is not first
    n = np.array([4.0, 4.0, 4.0])
    w = np.array([0.0, 0.0, -40.0])  # mean cumulative EFE 0, 0, -10
    assert ucb_select(n, w, np.zeros(3), 12, c=1.0) == 2
    # the best-valued child has been visited more: an exploration-only rule picks another
    n = np.array([3.0, 3.0, 4.0])
    w = np.array([3.0, 3.0, -20.0])
    assert ucb_select(n, w, np.zeros(3), 10, c=1.0) == 2
    # untried children come first, best immediate EFE first
    n = np.array([2.0, 0.0, 0.0])
    assert ucb_select(n, np.array([-9.0, 0, 0]), np.array([0.0, 1.0, -1.0]), 2, c=1.0) == 2


class _ToyExpander:
    """Root actions 0 and 1 have equal immediate EFE; only action 0 leads on to good values.
    Expanders return (actions, G, G without epistemic terms, child keys)."""

    root_key = "root"

    def root(self):
        return np.array([0, 1]), np.zeros(2), np.zeros(2), ["good", "bad"]

    def expand(self, key):
        g = np.array([-1.0, -1.0]) if key == "good" else np.array([0.0, 0.0])
        return np.array([0, 1]), g, np.zeros(2), [key, key]


def test_visits_follow_deeper_values():
    d = search(_ToyExpander(), MCTSConfig(depth=4, simulations=40, c=0.5), np.random.default_rng(0))
    assert d.action == 0
    assert d.visits[0] > 2 * d.visits[1]  # would be an even split if selection ignored values
    np.testing.assert_allclose(d.Q, [-3.0, 0.0])


class _PingPong:
    """Two neighbouring states A and B worth 1 nat of information each; the other way from the
    root, a corridor C1, C2 leads to C3 worth 3 nats (then a dead end D). Counting information
    on every visit makes bouncing between A and B the best plan (4 nats in 4 steps); counting it
    once per path does not (2 nats), so the far, richer C3 wins."""

    root_key = "root"
    values = {"A": 1.0, "B": 1.0, "C1": 0.0, "C2": 0.0, "C3": 3.0, "D": 0.0, "root": 0.0}
    links = {"root": ["A", "C1"], "A": ["B", "root"], "B": ["A", "root"], "C1": ["C2", "root"],
             "C2": ["C3", "C1"], "C3": ["D", "C2"], "D": ["D", "C3"]}

    def _step(self, key):
        nxt = self.links[key]
        return np.array([0, 1]), -np.array([self.values[k] for k in nxt]), np.zeros(2), nxt

    def root(self):
        return self._step("root")

    def expand(self, key):
        return self._step(key)


def test_information_counted_once_per_path_stops_ping_pong():
    cfg = MCTSConfig(depth=4, simulations=300)
    plain = search(_PingPong(), cfg, np.random.default_rng(0))
    once = search(_PingPong(), replace(cfg, count_information_once=True), np.random.default_rng(0))
    assert plain.action == 0 and plain.Q[0] == pytest.approx(-4.0)  # A, B, A, B
    assert once.action == 1 and once.Q[1] == pytest.approx(-3.0)  # C1, C2, C3, D
    assert once.Q[0] == pytest.approx(-2.0)  # A and B once each


def test_discount_prefers_information_sooner():
    cfg = MCTSConfig(depth=4, simulations=300, count_information_once=True, discount=0.5)
    d = search(_PingPong(), cfg, np.random.default_rng(0))
    assert d.action == 0  # 1 + 0.5 * 1 = 1.5 now beats 0.25 * 3 = 0.75 later
    np.testing.assert_allclose(d.Q, [-1.5, -0.75])


@pytest.mark.parametrize("seed", range(5))
def test_mcts_agrees_with_enumeration_on_small_models(seed):
    rng = np.random.default_rng(seed)
    arrays, _ = random_dense(rng, (3,), (3,), (4,))
    qs = [rng.dirichlet(np.ones(3))]
    depth = 3
    obj = efe.full()
    pol = enumerate_policies(arrays.num_controls, depth)
    G = evaluate_policies(arrays, qs, pol, obj)
    best_first = np.array([G[pol[:, 0, 0] == a].min() for a in range(3)])
    order = np.sort(best_first)
    cfg = MCTSConfig(depth=depth, simulations=1500, c=0.5)
    d = mcts(prepare(arrays, local=False), qs, obj, config=cfg, rng=seed)
    near_best = np.flatnonzero(best_first <= order[0] + 1e-3)  # (nearly) tied first actions all count
    assert d.action[0] in near_best
    # the best branch's backed-up value approaches its exhaustive EFE
    i = d.actions.tolist().index([d.action[0]])
    assert abs(d.Q[i] - best_first.min()) < 0.25 * (order[1] - order[0]) + 0.05


def test_mcts_agrees_with_enumeration_multi_factor():
    rng = np.random.default_rng(11)
    arrays, _ = random_dense(rng, (3, 2), (2, 2), (4, 3))
    qs = [rng.dirichlet(np.ones(3)), rng.dirichlet(np.ones(2))]
    obj = efe.pymdp_like(use_param_info_gain=True)
    pol = enumerate_policies(arrays.num_controls, 2)
    G = evaluate_policies(arrays, qs, pol, obj)
    d = mcts(prepare(arrays, local=False), qs, obj, config=MCTSConfig(depth=2, simulations=600), rng=0)
    assert d.action == tuple(int(x) for x in pol[np.argmin(G), 0])


def _goal_arrays(goal_cell=(6, 1), depth=10):
    G, poses, index = corridor_rooms()
    goal = index[goal_cell]
    C_states = np.zeros(len(poses))
    C_states[goal] = 1.0
    arrays = graph_model(
        G, poses, C_states=[C_states], target_pose=poses[goal], goal_states=np.array([goal]),
        inductive_depth=depth,
    )
    return G, poses, index, goal, arrays


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("mode", ["goal", "full"])
def test_mcts_reaches_toward_goal_six_steps_away(seed, mode):
    G, poses, index, goal, arrays = _goal_arrays()
    start = index[(0, 1)]
    dist = nx.single_source_shortest_path_length(G, goal)
    assert dist[start] == 6
    obj = efe.goal() if mode == "goal" else efe.full()
    qs = [np.eye(len(poses))[start]]
    d = mcts(prepare(arrays), qs, obj, config=MCTSConfig(depth=10, simulations=30), rng=seed)
    nxt = int(arrays.B[0].succ[start, d.action, 0])
    assert dist[nxt] == 5


def test_mcts_walks_the_whole_corridor_to_the_goal():
    G, poses, index, goal, arrays = _goal_arrays(goal_cell=(8, 1))
    s = index[(0, 1)]
    rng = np.random.default_rng(0)
    obj = efe.goal()
    prep = prepare(arrays)
    for _ in range(12):
        if s == goal:
            break
        d = mcts(prep, [np.eye(len(poses))[s]], obj, config=MCTSConfig(), rng=rng)
        s = int(arrays.B[0].succ[s, d.action, 0])
    assert s == goal


def test_mcts_is_deterministic_given_seed():
    _, poses, index, _, arrays = _goal_arrays()
    qs = [np.eye(len(poses))[index[(1, 1)]]]
    cfg = MCTSConfig(sample=True, gamma=1.0)
    a = mcts(prepare(arrays), qs, efe.full(), config=cfg, rng=np.random.default_rng(5))
    b = mcts(prepare(arrays), qs, efe.full(), config=cfg, rng=np.random.default_rng(5))
    assert a.action == b.action
    np.testing.assert_array_equal(a.visits, b.visits)
    np.testing.assert_array_equal(a.probs, b.probs)


def test_expansion_only_over_allowed_moves():
    G, poses, index, goal, arrays = _goal_arrays()
    s = index[(4, 1)]  # corridor: east, west and stay only
    acts = allowed_actions(arrays.B[0], s, STAY)
    assert sorted(acts.tolist()) == [0, 6, STAY]
    d = mcts(prepare(arrays), [np.eye(len(poses))[s]], efe.exploration(), rng=0)
    assert sorted(d.actions.tolist()) == [0, 6, STAY]


@pytest.mark.parametrize("prune", [True, False])
def test_flagged_direction_never_chosen(prune):
    # a symmetric spot: moving east or west along a corridor looks the same except collision
    G = nx.path_graph(9)
    poses = np.stack([np.arange(9.0), np.zeros(9)], axis=1)
    arrays = graph_model(G, poses, visited=np.ones(9, bool))
    s = 4
    for flagged in (0, 6):
        flags = np.zeros(13, dtype=bool)
        flags[flagged] = True
        for seed in range(4):
            cfg = MCTSConfig(prune_obstacles=prune, simulations=30, depth=4)
            obj = efe.objective([(efe.collision, 1.0), (efe.state_preference, 1.0)])
            d = mcts(prepare(arrays), [np.eye(9)[s]], obj, flags, cfg, rng=seed)
            assert d.action != flagged
            if prune:
                assert flagged not in d.actions.tolist()

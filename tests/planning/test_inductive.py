"""Inductive term (Eq. 9): backward reachability from preferred states."""

from __future__ import annotations

import networkx as nx
import numpy as np
import pytest
from planning_builders import chain, graph_model

from cogmap.genmodel.transitions import DenseTransitions
from cogmap.planning import efe, inductive
from cogmap.planning.arrays import prepare
from cogmap.planning.context import LocalStep
from cogmap.planning.testing import graph_arrays, lattice_graph

ALL = np.arange(13)


def _H(arrays, s):
    ctx = LocalStep(prepare(arrays), (s,), (1.0,), ALL)
    return efe.inductive(ctx)


@pytest.mark.parametrize("depth", [4, 7, 11])
def test_chain_action_toward_goal_is_strictly_best_within_horizon(depth):
    G, poses = chain(12)
    arrays = graph_model(G, poses, goal_states=np.array([11]), inductive_depth=depth)
    for s in range(12):
        H = _H(arrays, s)
        steps = 11 - s
        if steps > depth:
            np.testing.assert_array_equal(H, 0.0)  # goal beyond the horizon: silent
        elif s == 11:
            # stay on the goal; moves that cannot leave it act as stay, the move back does not
            assert H[12] > 0 and H[12] > H[6]
        else:
            east = 0
            assert H[east] > 0
            assert np.all(H[east] > np.delete(H, east)), (s, H)


def test_silent_without_goal():
    G, poses = chain(12)
    arrays = graph_model(G, poses, goal_states=np.array([], dtype=np.int64))
    for s in range(12):
        np.testing.assert_array_equal(_H(arrays, s), 0.0)
    arrays = graph_model(G, poses)  # goal_states=None
    np.testing.assert_array_equal(_H(arrays, 10), 0.0)


def test_transitions_below_threshold_do_not_count():
    G, poses = chain(6)
    arrays = graph_model(
        G, poses, visited=np.array([1, 1, 1, 0, 1, 1], bool), goal_states=np.array([5]),
        inductive_threshold=0.6,
    )
    d = prepare(arrays).dist
    assert d[5] == 0 and d[4] == 1
    assert np.all(d[:4] == inductive.UNREACHABLE)  # the 2-3 and 3-4 moves are uncertain (0.5)


def test_reachability_matches_pymdp_generate_I_matrix():
    pytest.importorskip("pymdp")
    import jax.numpy as jnp
    from pymdp.control import generate_I_matrix

    G, poses = chain(9)
    arrays = graph_model(G, poses, goal_states=np.array([8]))
    B = arrays.live_B(0)
    depth = 5
    H = np.zeros(9)
    H[8] = 1.0
    ref = np.asarray(generate_I_matrix([jnp.asarray(H)], [jnp.asarray(B)], 0.5, depth)[0])
    src, dst = DenseTransitions(B).edges(0.5, 9)
    ours = inductive.reachability_matrix(inductive.goal_distances(src, dst, H > 0, 9, depth), depth)
    np.testing.assert_array_equal(ours, ref)


def test_bfs_on_large_sparse_map_matches_networkx():
    rng = np.random.default_rng(0)
    G, poses = lattice_graph(3000, rng)
    arrays = graph_arrays(G, poses, goal_states=np.array([17, 2000]), inductive_depth=12)
    d = prepare(arrays).dist
    ref = nx.multi_source_dijkstra_path_length(G, {17, 2000}, cutoff=12)
    expect = np.full(3000, inductive.UNREACHABLE)
    for k, v in ref.items():
        expect[k] = v
    np.testing.assert_array_equal(d, expect)

"""A* on cognitive-map graphs and occupancy grids."""

from __future__ import annotations

import math

import networkx as nx
import numpy as np
import pytest
from planning_builders import corridor_rooms, graph_model

from cogmap.planning.astar import astar_graph, astar_grid
from cogmap.planning.testing import lattice_graph


def _weighted(G, poses):
    for u, v in G.edges:
        G.edges[u, v]["weight"] = float(np.linalg.norm(poses[u] - poses[v]))
    return G


@pytest.mark.parametrize("seed", range(3))
def test_graph_astar_matches_networkx(seed):
    rng = np.random.default_rng(seed)
    G, poses = lattice_graph(300, rng, drop=0.3)
    _weighted(G, poses)
    for _ in range(10):
        s, t = (int(x) for x in rng.integers(300, size=2))
        path, cost = astar_graph(G, s, t, poses=poses)
        try:
            ref = nx.dijkstra_path_length(G, s, t)
        except nx.NetworkXNoPath:
            assert path is None and math.isinf(cost)
            continue
        assert cost == pytest.approx(ref)
        assert path[0] == s and path[-1] == t
        assert sum(G.edges[a, b]["weight"] for a, b in zip(path, path[1:], strict=False)) == pytest.approx(ref)


def test_graph_astar_uses_pose_attributes_without_weights():
    G, poses, index = corridor_rooms()
    for i in G.nodes:
        G.nodes[i]["pose"] = poses[i]
    path, cost = astar_graph(G, index[(0, 0)], index[(8, 2)])
    ref = nx.shortest_path_length(_weighted(G.copy(), poses), index[(0, 0)], index[(8, 2)], weight="weight")
    assert cost == pytest.approx(ref)


def test_sparse_transitions_astar_with_threshold():
    G, poses, index = corridor_rooms()
    arrays = graph_model(G, poses)
    B = arrays.B[0]
    s, t = index[(0, 1)], index[(8, 1)]
    path, cost = astar_graph(B, s, t, poses=poses, threshold=0.5)
    ref = nx.dijkstra_path_length(_weighted(G.copy(), poses), s, t)
    assert cost == pytest.approx(ref)
    # the corridor's middle cell believed blocked (uncertain moves below threshold): no path
    visited = np.ones(len(poses), bool)
    visited[index[(4, 1)]] = False
    arrays = graph_model(G, poses, visited=visited)
    path, cost = astar_graph(arrays.B[0], s, t, poses=poses, threshold=0.5)
    assert path is None and math.isinf(cost)


def test_grid_straight_and_diagonal():
    occ = np.zeros((5, 5), bool)
    path, length = astar_grid(occ, (0, 0), (4, 4), resolution=0.5)
    assert length == pytest.approx(4 * math.sqrt(2) * 0.5)
    assert path[0] == (0, 0) and path[-1] == (4, 4) and len(path) == 5
    path, length = astar_grid(occ, (0, 0), (0, 4), resolution=0.1)
    assert length == pytest.approx(0.4)


def test_grid_detour_around_wall_and_no_corner_cutting():
    occ = np.array(
        [
            [0, 0, 0, 0, 0],
            [0, 1, 1, 1, 0],
            [0, 0, 0, 1, 0],
            [1, 1, 0, 1, 0],
            [0, 0, 0, 1, 0],
        ],
        bool,
    )
    path, length = astar_grid(occ, (2, 0), (2, 4))
    # up the left column, along the top row, down the right column: both diagonal
    # shortcuts ((1,0)->(0,1) and (0,3)->(1,4)) would cut an occupied corner, so 8 unit moves
    assert length == pytest.approx(8.0)
    assert len(path) == 9
    for (r0, c0), (r1, c1) in zip(path, path[1:], strict=False):
        assert not occ[r1, c1]
        if r0 != r1 and c0 != c1:
            assert not occ[r1, c0] and not occ[r0, c1]
    # a diagonal gap between two occupied cells is not passable
    occ = np.array([[0, 1], [1, 0]], bool)
    assert astar_grid(occ, (0, 0), (1, 1))[0] is None


def test_grid_matches_networkx_on_random_maps():
    rng = np.random.default_rng(1)
    for _ in range(5):
        occ = rng.random((20, 20)) < 0.25
        free = list(zip(*np.nonzero(~occ), strict=True))
        G = nx.Graph()
        for r, c in free:
            for dr, dc in ((0, 1), (1, 0), (1, 1), (1, -1)):
                rr, cc = r + dr, c + dc
                if 0 <= rr < 20 and 0 <= cc < 20 and not occ[rr, cc]:
                    if dr and dc and (occ[r + dr, c] or occ[r, c + dc]):
                        continue
                    G.add_edge((r, c), (rr, cc), weight=math.hypot(dr, dc))
        a, b = (tuple(int(x) for x in free[i]) for i in rng.choice(len(free), 2, replace=False))
        path, length = astar_grid(occ, a, b, resolution=0.05)
        try:
            ref = nx.dijkstra_path_length(G, a, b) * 0.05
        except (nx.NetworkXNoPath, nx.NodeNotFound):
            assert path is None
            continue
        assert length == pytest.approx(ref)

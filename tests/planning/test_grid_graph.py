"""The shared 8-connected grid graph against a cell-by-cell construction."""

import numpy as np

from cogmap.planning.grid_graph import grid_graph


def _edges(passable, cost):
    out = {}
    H, W = passable.shape
    for i in range(H):
        for j in range(W):
            for di, dj in ((0, 1), (1, 0), (1, 1), (1, -1)):
                a, b = i + di, j + dj
                if not (0 <= a < H and 0 <= b < W and passable[i, j] and passable[a, b]):
                    continue
                if di and dj and not (passable[a, j] and passable[i, b]):
                    continue
                out[(i * W + j, a * W + b)] = (np.sqrt(2.0) if di and dj else 1.0) * (cost[i, j] + cost[a, b]) / 2
    return out


def test_grid_graph_matches_a_cell_by_cell_construction():
    rng = np.random.default_rng(1)
    passable = rng.random((7, 9)) < 0.7
    cost = 1.0 + rng.random((7, 9))
    for c, ref_cost in ((None, np.ones((7, 9))), (cost, cost)):
        g = grid_graph(passable, c).tocoo()
        got = {(int(r), int(k)): float(v) for r, k, v in zip(g.row, g.col, g.data, strict=True)}
        ref = _edges(passable, ref_cost)
        assert got.keys() == ref.keys() and len(ref) > 20
        assert all(np.isclose(got[e], ref[e]) for e in ref)

"""The frontier pull of the DVBF-LM explorer: counts, distances and paths against hand-built grids and an
independent shortest-path search (networkx), and the controls that follow a path."""

import networkx as nx
import numpy as np
import pytest

from cogmap.planning.frontier_pull import blocked, cell_cost, descend, free_steps, frontier_distance, pursue, sweep


def test_sweep_counts_a_beam_once_per_cell_and_its_end():
    crossed, ended = np.zeros((10, 10), np.int64), np.zeros((10, 10), np.int64)
    # from the centre of cell (1, 5) (cells of 0.1) one beam east ending at x = 0.75, three hitting nothing
    pose = np.array([[0.15, 0.55, 0.0]])
    scan = np.array([[0.6, 0.7, 0.7, 0.7]])  # beams at 0, pi/2, pi, 3pi/2; range 0.7 = no return
    sweep(crossed, ended, pose, scan, lidar_range=0.7, extent=1.0)
    # east: samples up to half a cell short of x = 0.75 cross cells 1..6, the return ends in cell 7
    assert crossed[2:7, 5].tolist() == [1] * 5 and crossed[7:, 5].sum() == 0
    assert ended[7, 5] == 1 and ended.sum() == 1
    # north: a beam at range crosses cells 5..9 (the rest lies outside the world) and ends nowhere
    assert crossed[1, 5:].tolist() == [4, 1, 1, 1, 1]  # cell (1, 5) is crossed by all four beams
    # west reaches the world's edge (clipped to cell 0), south too
    assert crossed[0, 5] == 1 and crossed[1, 0] == 1


def test_sweep_rejects_bad_shapes():
    g = np.zeros((4, 4), np.int64)
    with pytest.raises(ValueError, match="poses"):
        sweep(g, g.copy(), np.zeros((2, 2)), np.zeros((2, 3)), 0.5, 1.0)
    with pytest.raises(ValueError, match="square"):
        sweep(g, np.zeros((4, 5), np.int64), np.zeros((1, 3)), np.zeros((1, 3)), 0.5, 1.0)


def _reference(cost: np.ndarray, frontier: np.ndarray) -> np.ndarray:
    """Multi-source cheapest paths on the same 8-connected graph, built cell by cell with networkx."""
    n = cost.shape[0]
    ok = np.isfinite(cost)
    g = nx.Graph()
    for i in range(n):
        for j in range(n):
            if not ok[i, j]:
                continue
            g.add_node((i, j))
            for di, dj in ((0, 1), (1, 0), (1, 1), (1, -1)):
                a, b = i + di, j + dj
                if not (0 <= a < n and 0 <= b < n and ok[a, b]):
                    continue
                if di and dj and not (ok[i + di, j] and ok[i, j + dj]):
                    continue
                g.add_edge((i, j), (a, b), weight=(np.sqrt(2.0) if di and dj else 1.0) * (cost[i, j] + cost[a, b]) / 2)
    d = nx.multi_source_dijkstra_path_length(g, [tuple(c) for c in np.argwhere(frontier)])
    out = np.full(cost.shape, np.inf)
    for (i, j), v in d.items():
        out[i, j] = v
    return out


def test_frontier_distance_matches_networkx_on_a_random_sensed_grid():
    rng = np.random.default_rng(3)
    crossed = rng.integers(0, 8, (16, 16)) * (rng.random((16, 16)) < 0.85)
    ended = (rng.random((16, 16)) < 0.03).astype(np.int64) * 3
    dist, cost = frontier_distance(crossed, ended, hit_min=2, min_crossed=3)
    assert np.array_equal(cost, cell_cost(crossed, ended, 2, 3))
    wall = (ended >= 2) & (ended >= 0.3 * (ended + crossed))
    unknown = np.pad((crossed < 3) & ~wall, 1)
    frontier = np.isfinite(cost) & (unknown[:-2, 1:-1] | unknown[2:, 1:-1] | unknown[1:-1, :-2] | unknown[1:-1, 2:])
    assert frontier.any() and np.isfinite(dist).sum() > frontier.sum()
    assert (cost[np.isfinite(cost)] > 1).any()  # some cells near a wall cost more
    np.testing.assert_allclose(dist, _reference(cost, frontier), atol=1e-9)


def test_cell_cost_walls_beams_and_clearance():
    crossed, ended = np.full((9, 9), 5), np.zeros((9, 9), np.int64)
    ended[4, 4] = 1
    assert np.isfinite(cell_cost(crossed, ended, hit_min=2)).all()  # one stray return is not a wall
    ended[4, 4], crossed[4, 4] = 2, 0  # a wall: beams end in it, none cross it
    cost = cell_cost(crossed, ended, hit_min=2)
    assert np.array_equal(np.isinf(cost), blocked(crossed, ended, hit_min=2))
    assert np.isinf(cost[3:6, 3:6]).all() and np.isfinite(cost).sum() == 81 - 9
    assert cost[4, 7] == 3.0 and cost[4, 8] == 1.0  # 3 cells from the wall: dearer; 4 cells: not
    crossed[0, 0] = 2
    assert np.isinf(cell_cost(crossed, ended, hit_min=2, min_crossed=3)[0, 0])  # too few beams
    mask = blocked(crossed, ended, hit_min=2)
    assert free_steps(np.array([[0.5, 0.5], [1.5, 0.5], [2.5, 1.5], [3.5, 3.5], [8.5, 8.5]]), mask, 9.0) == 2
    assert free_steps(np.array([[0.5, 0.5], [0.5, 8.5]]), mask, 9.0) == 1  # never enters
    crossed[4, 4] = 20  # 2 returns among 22 beams through the cell: free space under smeared returns
    assert np.isfinite(cell_cost(crossed, ended, hit_min=2, wall_fraction=0.3)[1:, 1:]).all()


def test_descend_walks_a_corridor_to_the_unexplored_end():
    # a well-seen corridor along x (columns j = 1..9), walls beside it, its east end not yet seen
    n = 16
    crossed, ended = np.zeros((n, n), np.int64), np.zeros((n, n), np.int64)
    crossed[0:12, 1:10] = 5
    ended[0:12, 0] = ended[0:12, 10] = 5  # walls at j = 0 and j = 10: passable j = 2..8
    dist, cost = frontier_distance(crossed, ended)
    path = descend(dist, cost, np.array([0.05, 0.55]), extent=1.6)  # cell (0, 5), the corridor's middle
    cells = np.floor(path / 0.1).astype(int)
    assert tuple(cells[0]) == (0, 5) and cells[-1][0] == 11  # ends at the last seen column
    assert dist[tuple(cells[-1])] == 0
    assert (cells[:, 1] == 5).all()  # down the middle, where cells are cheap
    d = dist[cells[:, 0], cells[:, 1]]
    assert (np.diff(d) < 0).all() and np.isclose(d[0], 11.0)
    # nothing reachable: no path
    none = np.full((n, n), np.inf)
    assert descend(none, none, np.array([0.05, 0.55]), extent=1.6).shape == (0, 2)


def test_pursue_follows_a_path_round_a_corner():
    path = np.array([[0.1 + 0.01 * k, 0.1] for k in range(30)] + [[0.39, 0.1 + 0.01 * k] for k in range(1, 30)])
    u = pursue(path, np.array([0.1, 0.1, 0.0]), steps=55, max_turn=0.35, max_step=0.01)
    assert u.shape == (55, 2) and np.allclose(u[:, 1], 0.01) and np.abs(u[:, 0]).max() <= 0.35 + 1e-12
    x, y, h = 0.1, 0.1, 0.0
    for turn, fwd in u:  # rotation before translation, as the maze world applies them
        h += turn
        x, y = x + fwd * np.cos(h), y + fwd * np.sin(h)
        assert np.hypot(*(path - [x, y]).T).min() < 0.02  # never far from the path
    assert y > 0.3  # turned the corner and went up
    assert np.allclose(u[:10, 0], 0.0)  # straight along the first leg
    # facing away, the first step turns round at once (as a candidate's first turn may), then follows
    back = pursue(path, np.array([0.1, 0.1, np.pi]), steps=5, max_turn=0.35, max_step=0.01)
    assert np.isclose(abs(back[0, 0]), np.pi) and np.allclose(back[1:, 0], 0.0)
    with pytest.raises(ValueError, match="non-empty"):
        pursue(np.zeros((0, 2)), np.zeros(3), 5, 0.35, 0.01)


def test_the_pull_leads_a_robot_out_of_what_it_has_sensed_in_a_pybullet_maze():
    """The explorer's pull on the grid of a 300-step operator walk (its scans at the true poses): the
    controls, executed in the pybullet maze, hit no wall and reach a frontier of that grid."""
    import dataclasses
    from types import SimpleNamespace

    from cogmap.dvbf.explore import STUDY_MI
    from cogmap.envs.maze import make_maze
    from cogmap.envs.maze_sim import MazeSim
    from cogmap.envs.maze_traversal import traverse
    from cogmap.genmodel.dvbf import DVBFConfig
    from cogmap.planning.mi_planner import MIPlanner

    maze = make_maze(2, "moderate", "small")
    tr = traverse(maze, 300, seed=3)
    mi = dataclasses.replace(STUDY_MI, pull_below=1.0)
    planner = MIPlanner(DVBFConfig(extent=maze.size, map_side=maze.map_side), mi, maze.size, seed=0)
    slam = SimpleNamespace(t=len(tr.poses) - 1, estimates=tr.poses, scans=tr.scans, estimate=tr.poses[-1])
    planner._sweep(slam)
    assert planner.swept == len(tr.poses) and planner.crossed.sum() > 0
    info = {"controls": np.zeros((0, mi.horizon, 2)), "free_steps": np.zeros(0, int), "scores": np.zeros(0),
            "best": 0, "pulled": False}
    planner._pull(slam, info)
    assert info["pulled"] and info["best"] == 0 and info["free_steps"][0] >= mi.obs_every
    dist, _ = frontier_distance(planner.crossed, planner.ended, mi.pull_hit_min, mi.pull_min_crossed)
    side = dist.shape[0]
    start = tuple(np.clip((tr.poses[-1, :2] / maze.size * side).astype(int), 0, side - 1))
    goal = np.floor(info["pull_path"][-1] / maze.size * side).astype(int)
    assert dist[tuple(goal)] == 0 and dist[start] > 0
    with MazeSim(maze) as sim:
        sim.reset(tr.poses[-1])
        hits, trail = 0, []
        for u in info["controls"][0][: info["free_steps"][0]]:
            pose, hit = sim.step(u)
            hits += int(hit)
            trail.append(pose[:2])
    assert hits == 0
    # the executed path ends at most half as far from the frontier as it started (measured: 13.1 -> 2.8 cells)
    cells = np.clip((np.array(trail) / maze.size * side).astype(int), 0, side - 1)
    d_end = dist[cells[-1, 0], cells[-1, 1]]
    assert d_end <= 0.5 * dist[start] or np.isinf(d_end)  # inf: it has left the sensed grid past the frontier

"""A* on the cognitive-map graph and on occupancy grids.

* :func:`astar_graph`: a networkx graph (edge attribute ``weight``, or the distance between
  node ``pose`` attributes) or sparse transitions (``succ``/``prob``) with edges above a
  probability threshold weighted by the metric distance between stored poses. The heuristic
  is the straight-line distance between poses (admissible for metric edge weights).
* :func:`astar_grid`: a boolean occupancy grid (True = occupied), 8-connected, diagonal moves
  not cutting occupied corners; returns the cell path and its length in metres.
"""

from __future__ import annotations

import heapq
import math

import numpy as np

from cogmap.genmodel.transitions import DenseTransitions, SparseTransitions


def _search(start, goal, neighbours, heuristic):
    """Generic A*: returns ``(path, cost)`` or ``(None, inf)``."""
    if start == goal:
        return [start], 0.0
    g = {start: 0.0}
    parent = {start: None}
    heap = [(heuristic(start), 0, start)]
    tick = 0
    closed = set()
    while heap:
        _, _, u = heapq.heappop(heap)
        if u in closed:
            continue
        if u == goal:
            path = [u]
            while parent[path[-1]] is not None:
                path.append(parent[path[-1]])
            return path[::-1], g[u]
        closed.add(u)
        gu = g[u]
        for v, w in neighbours(u):
            if v in closed:
                continue
            nv = gu + w
            if nv < g.get(v, math.inf):
                g[v] = nv
                parent[v] = u
                tick += 1
                heapq.heappush(heap, (nv + heuristic(v), tick, v))
    return None, math.inf


def sparse_graph_edges(B, poses: np.ndarray, n: int, threshold: float = 0.5) -> dict:
    """Adjacency ``{s: [(t, metric distance), ...]}`` of transitions with probability above
    ``threshold`` in a transition factor (``B.edges``)."""
    src, dst = B.edges(threshold, n)
    w = np.linalg.norm(poses[src] - poses[dst], axis=1)
    adj: dict = {}
    for s, t, d in zip(src.tolist(), dst.tolist(), w.tolist(), strict=True):
        lst = adj.setdefault(s, [])
        if all(t != x for x, _ in lst):
            lst.append((t, d))
    return adj


def astar_graph(graph, start, goal, poses=None, threshold: float = 0.5, weight: str = "weight"):
    """Shortest path on a cognitive map with A* (straight-line heuristic between poses).

    Parameters
    ----------
    graph : networkx.Graph or DenseTransitions or SparseTransitions
        A networkx graph (edge attribute ``weight``, else the distance between node ``pose``
        attributes / ``poses``, else 1), or a transition factor whose edges above ``threshold`` are
        weighted by the metric distance between stored poses (then ``poses`` is required).
    start, goal : hashable
        Start and goal nodes (state indices for a transition factor).
    poses : array_like, optional
        ``(n, 2)`` float stored poses, metres; used instead of node ``pose`` attributes.
    threshold : float, optional
        Transition probability above which a move is an edge (transition factors), default 0.5.
    weight : str, optional
        Name of the edge weight attribute (networkx graphs), default ``"weight"``.

    Returns
    -------
    path : list or None
        Nodes from ``start`` to ``goal``, or None when unreachable.
    cost : float
        Path length (metres for metric weights), ``inf`` when unreachable.

    Raises
    ------
    ValueError
        If ``graph`` is a transition factor and ``poses`` is missing.
    """
    if isinstance(graph, DenseTransitions | SparseTransitions):
        if poses is None:
            raise ValueError("astar_graph on a transition factor needs the stored poses")
        P = np.asarray(poses, dtype=float)
        adj = sparse_graph_edges(graph, P, P.shape[0], threshold)
        gx, gy = P[goal]

        def heuristic(u):
            return math.hypot(P[u][0] - gx, P[u][1] - gy)

        return _search(start, goal, lambda u: adj.get(u, ()), heuristic)

    def pose_of(u):
        if poses is not None:
            return poses[u]
        return graph.nodes[u].get("pose")

    gp = pose_of(goal)

    def heuristic(u):
        p = pose_of(u)
        if p is None or gp is None:
            return 0.0
        return math.hypot(p[0] - gp[0], p[1] - gp[1])

    def neighbours(u):
        for v, data in graph.adj[u].items():
            w = data.get(weight)
            if w is None:
                pu, pv = pose_of(u), pose_of(v)
                w = 1.0 if pu is None or pv is None else math.hypot(pu[0] - pv[0], pu[1] - pv[1])
            yield v, float(w)

    return _search(start, goal, neighbours, heuristic)


_MOVES = [(-1, -1), (-1, 0), (-1, 1), (0, -1), (0, 1), (1, -1), (1, 0), (1, 1)]


def astar_grid(occupied: np.ndarray, start, goal, resolution: float = 1.0):
    """8-connected A* on a boolean occupancy grid; diagonal steps may not cut an occupied corner.

    Parameters
    ----------
    occupied : array_like
        ``(H, W)`` bool, ``occupied[row, col]`` True where occupied.
    start, goal : tuple of int
        ``(row, col)`` cells.
    resolution : float, optional
        Cell size in metres, default 1.

    Returns
    -------
    path : list of tuple or None
        Cells ``(row, col)`` from ``start`` to ``goal``; None when unreachable or when an end cell is
        outside the grid or occupied.
    length : float
        Path length in metres (``inf`` when there is no path).
    """
    occ = np.asarray(occupied, dtype=bool)
    H, W = occ.shape
    start, goal = tuple(int(x) for x in start), tuple(int(x) for x in goal)
    for p in (start, goal):
        if not (0 <= p[0] < H and 0 <= p[1] < W) or occ[p]:
            return None, math.inf
    free = ~occ
    gr, gc = goal
    s2 = math.sqrt(2.0)

    def heuristic(u):  # octile distance (exact on an empty grid)
        dr, dc = abs(u[0] - gr), abs(u[1] - gc)
        return (dr + dc) + (s2 - 2.0) * min(dr, dc)

    def neighbours(u):
        r, c = u
        for dr, dc in _MOVES:
            rr, cc = r + dr, c + dc
            if not (0 <= rr < H and 0 <= cc < W) or not free[rr, cc]:
                continue
            if dr and dc:
                if not (free[r + dr, c] and free[r, c + dc]):
                    continue
                yield (rr, cc), s2
            else:
                yield (rr, cc), 1.0

    path, cost = _search(start, goal, neighbours, heuristic)
    return path, cost * resolution

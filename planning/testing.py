"""Synthetic topological maps for tests, examples and benchmarks.

:func:`graph_arrays` turns a graph with 2-D node poses into single-factor
:class:`~.arrays.PlanningArrays` with sparse transitions: 12 heading controls (30 degrees apart)
plus a structural stay control (last), each edge mapped to the heading nearest its direction.
:func:`lattice_graph` builds the grid-like map of the benchmark.
"""

from __future__ import annotations

import networkx as nx
import numpy as np

from cogmap.genmodel import SparseTransitions
from cogmap.genmodel.numerics import wrap_angle

from .arrays import PlanningArrays

HEADINGS = np.arange(12) * (2 * np.pi / 12)
STAY = 12


def heading_index(dx: float, dy: float) -> int:
    ang = np.arctan2(dy, dx) % (2 * np.pi)
    diff = np.abs(wrap_angle(HEADINGS - ang))
    return int(np.argmin(diff))


def lattice(cells, allowed=None) -> nx.Graph:
    """The 8-connected graph of lattice ``cells`` (node ``i`` is ``cells[i]``), without the edges
    ``allowed(x, y, dx, dy)`` refuses."""
    index = {c: i for i, c in enumerate(cells)}
    G = nx.Graph()
    G.add_nodes_from(range(len(cells)))
    for (x, y), i in index.items():
        for dx, dy in ((1, 0), (0, 1), (1, 1), (1, -1)):
            j = index.get((x + dx, y + dy))
            if j is not None and (allowed is None or allowed(x, y, dx, dy)):
                G.add_edge(i, j)
    return G


def lattice_graph(n: int, rng: np.random.Generator, drop: float = 0.1) -> tuple[nx.Graph, np.ndarray]:
    """About ``n`` nodes on a 1 m lattice, 8-connected, with ``drop`` of the cells removed
    (obstacles); relabelled 0..n-1 by position, poses returned as an (n, 2) array."""
    side = int(np.ceil(np.sqrt(n / (1 - drop))))
    cells = [(x, y) for y in range(side) for x in range(side)]
    keep = rng.permutation(len(cells))[:n]
    keep.sort()
    cells = [cells[i] for i in keep]
    return lattice(cells), np.asarray(cells, dtype=float)


def graph_arrays(
    G: nx.Graph,
    poses: np.ndarray,
    *,
    visited: np.ndarray | None = None,
    num_obs: int | None = None,
    p_move: float = 0.9,
    p_move_unvisited: float = 0.5,
    count_scale: float = 10.0,
    rng: np.random.Generator | None = None,
    **kwargs,
) -> PlanningArrays:
    """Single-factor arrays for graph ``G`` (nodes 0..n-1) with stored ``poses``.

    A move along an edge succeeds with ``p_move`` (else stays) between visited states and
    with ``p_move_unvisited`` when either end is unvisited; Dirichlet counts are
    ``count_scale`` times the probabilities for visited columns and twice them otherwise.
    Each visited state has its own outcome (likelihood 0.8 on it, the rest spread), unvisited
    states have uniform likelihood columns; ``pA`` follows the same pattern. Extra keyword
    arguments go to :class:`PlanningArrays` (``C_states``, ``target_pose``, ``goal_states``...).
    """
    rng = np.random.default_rng(0) if rng is None else rng
    n = G.number_of_nodes()
    visited = np.ones(n, dtype=bool) if visited is None else np.asarray(visited, dtype=bool)
    U = 13
    slots = 2
    B = SparseTransitions.empty(n, U, slots, with_counts=True)
    B.counts[:] = 0.0
    B.counts[:, :, 0] = 1.0
    for s in range(n):
        B.counts[s, STAY, 0] = count_scale
        for t in G.neighbors(s):
            h = heading_index(*(poses[t] - poses[s]))
            known = visited[s] and visited[t]
            p = p_move if known else p_move_unvisited
            scale = count_scale if known else 2.0
            B.succ[s, h] = (t, s)
            B.prob[s, h] = (p, 1 - p)
            B.counts[s, h] = (scale * p, scale * (1 - p))
    vis_idx = np.flatnonzero(visited)
    no = max(1, len(vis_idx)) if num_obs is None else num_obs
    A = np.full((no, n), 1.0 / no)
    pA = np.ones((no, n))
    for o, s in enumerate(vis_idx[:no]):
        A[:, s] = 0.2 / max(1, no - 1)
        A[o, s] = 0.8 if no > 1 else 1.0
        pA[:, s] = 0.5
        pA[o, s] = 8.0
    A /= A.sum(axis=0, keepdims=True)
    kw = dict(
        C_states=[np.zeros(n)],
        stay=(STAY,),
        poses=np.asarray(poses, dtype=float),
        pose_sigma=1.0,
    )
    kw.update(kwargs)
    return PlanningArrays(
        A=[A],
        A_deps=((0,),),
        B=[B],
        C=[np.zeros(no)],
        num_states=(n,),
        num_obs=(no,),
        num_controls=(U,),
        pA=[pA],
        pB=[None],
        **kw,
    )

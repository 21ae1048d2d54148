"""Shared builders for planning tests: random dense models and small topological maps."""

from __future__ import annotations

import networkx as nx
import numpy as np

from cogmap.planning.arrays import PlanningArrays
from cogmap.planning.testing import graph_arrays, lattice


def _norm(x, axis=0):
    return x / x.sum(axis=axis, keepdims=True)


def random_dense(rng, num_states=(4,), num_controls=(3,), num_obs=(5,), A_deps=None, counts=True):
    """A random multi-factor model as PlanningArrays, plus the raw lists (for pymdp)."""
    F = len(num_states)
    if A_deps is None:
        A_deps = [list(range(F)) for _ in num_obs]
    A = []
    for o, deps in zip(num_obs, A_deps, strict=True):
        A.append(_norm(rng.gamma(0.7, size=(o, *[num_states[f] for f in deps])) + 1e-3))
    B = [
        _norm(rng.gamma(0.5, size=(n, n, u)) + 1e-3)
        for n, u in zip(num_states, num_controls, strict=True)
    ]
    C = [rng.normal(size=o) for o in num_obs]
    pA = pB = None
    if counts:
        pA = [a * rng.uniform(1, 8) + rng.uniform(0.1, 1.0, size=a.shape) for a in A]
        pB = [b * rng.uniform(1, 8) + rng.uniform(0.1, 1.0, size=b.shape) for b in B]
    arrays = PlanningArrays(
        A=A,
        A_deps=tuple(tuple(d) for d in A_deps),
        B=B,
        C=C,
        num_states=tuple(num_states),
        num_obs=tuple(num_obs),
        num_controls=tuple(num_controls),
        pA=pA,
        pB=pB,
    )
    return arrays, dict(A=A, B=B, C=C, pA=pA, pB=pB, A_deps=[list(d) for d in A_deps])


def corridor_rooms():
    """Two 3x3 rooms joined by a 3-node corridor on a 1 m lattice (poses, graph)."""
    cells = []
    for x in range(3):
        for y in range(3):
            cells.append((x, y))  # room 1
    cells += [(3, 1), (4, 1), (5, 1)]  # corridor
    for x in range(6, 9):
        for y in range(3):
            cells.append((x, y))  # room 2
    def allowed(x, y, dx, dy):  # the corridor is one cell wide: no diagonal entries
        return not ((3 <= x <= 5 or 3 <= x + dx <= 5) and dy != 0)

    index = {c: i for i, c in enumerate(cells)}
    return lattice(cells, allowed), np.asarray(cells, dtype=float), index


def chain(n=12):
    G = nx.path_graph(n)
    poses = np.stack([np.arange(n, dtype=float), np.zeros(n)], axis=1)
    return G, poses


def graph_model(G, poses, **kw):
    kw.setdefault("p_move", 0.95)
    return graph_arrays(G, poses, **kw)

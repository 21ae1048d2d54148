"""The cognitive map as a networkx graph: a mirror of the arrays for export, plots and A*.

Nodes are live states (attributes ``x``, ``y`` when the model has poses, and ``obs``: the
observation ids whose likelihood at that state exceeds ``obs_threshold``); edges are
``(s, s', key=control)`` with attribute ``prob`` = believed transition probability. Jitted or
hot-loop code never touches this graph.
"""

from __future__ import annotations

from pathlib import Path

import networkx as nx

from .model import Model


def to_graph(
    model: Model,
    factor: int = 0,
    modality: int | None = 0,
    min_prob: float = 0.05,
    obs_threshold: float = 0.5,
) -> nx.MultiDiGraph:
    """Build the map graph of ``factor`` (edges with probability >= ``min_prob``, no self-loops)."""
    n = model.num_states[factor]
    g = nx.MultiDiGraph(factor=model.factors[factor].name)
    pose = model.pose if model.pose is not None and model.pose.factor == factor else None
    A = None
    if modality is not None and model.modalities and model.A_deps[modality] == (factor,):
        A = model.A[modality]
    for s in range(n):
        attrs = {}
        if pose is not None:
            attrs["x"], attrs["y"] = float(pose.poses[s, 0]), float(pose.poses[s, 1])
        if A is not None:
            attrs["obs"] = ",".join(str(o) for o in A.outcomes_above(s, obs_threshold))
        g.add_node(s, **attrs)
    stay = model.factors[factor].stay
    B = model.B[factor]
    for u in range(model.factors[factor].num_controls):
        if u == stay:
            continue
        for a, b, p in zip(*B.control_edges(u, n, min_prob), strict=True):
            g.add_edge(int(a), int(b), key=int(u), control=int(u), prob=float(p))
    return g


def write_graphml(model: Model, path, **kwargs) -> Path:
    """Export :func:`to_graph` to GraphML."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    nx.write_graphml(to_graph(model, **kwargs), path)
    return path

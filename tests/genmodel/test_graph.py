"""The networkx mirror follows the arrays and exports GraphML."""

import networkx as nx
import numpy as np

from cogmap.genmodel import Factor, Modality, ModelSpec, PoseSpec, compile
from cogmap.genmodel.graph import to_graph, write_graphml
from cogmap.genmodel.transitions import SparseTransitions


def chain_model(sparse):
    n = 4
    B = np.zeros((n, n, 3))
    B[:, :, 0] = np.eye(n)
    B[:, :, 1] = np.eye(n, k=-1) + np.diag([0] * (n - 1) + [1])  # move right, wall at the end
    B[:, :, 2] = np.eye(n, k=1) + np.diag([1] + [0] * (n - 1))
    spec = ModelSpec(
        [Factor("s", n, 3, stay=0)],
        [Modality("o", n, ("s",))],
        A={"o": np.eye(n)},
        B={"s": B},
        pose=PoseSpec("s", np.c_[np.arange(n), np.zeros(n)], headings=[0.0, np.pi]),
    )
    model = compile(spec)
    if sparse:
        model.B[0] = SparseTransitions.from_dense(model.B[0].prob)
    return model


def test_graph_mirrors_transitions(tmp_path):
    for sparse in (False, True):
        g = to_graph(chain_model(sparse))
        assert sorted(g.nodes) == [0, 1, 2, 3]
        assert g.nodes[2]["x"] == 2.0 and g.nodes[2]["obs"] == "2"
        assert sorted((a, b, k) for a, b, k in g.edges(keys=True)) == [
            (0, 1, 1), (1, 0, 2), (1, 2, 1), (2, 1, 2), (2, 3, 1), (3, 2, 2)
        ]
        assert nx.shortest_path(g, 0, 3) == [0, 1, 2, 3]
    path = write_graphml(chain_model(True), tmp_path / "map.graphml")
    back = nx.read_graphml(path)
    assert back.number_of_nodes() == 4 and back.number_of_edges() == 6
    assert float(back.nodes["3"]["x"]) == 3.0

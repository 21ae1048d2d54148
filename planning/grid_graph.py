"""The 8-connected graph of a grid's passable cells, for ``scipy.sparse.csgraph`` searches.

Shared by the sensed grid's geodesic growth (:mod:`.sensed`), the frontier pull (:mod:`.frontier_pull`)
and the baselines' grid navigation. A diagonal step needs both side cells passable (no corner cutting);
a step weighs its length (1 or sqrt(2) cells) times the mean cost of its two cells.
"""

from __future__ import annotations

import numpy as np


def grid_graph(passable, cost=None):
    """The graph of ``passable`` cells as a CSR matrix over flat indices ``row * W + col``.

    Parameters
    ----------
    passable : numpy.ndarray of bool, shape (H, W)
        Cells a path may use.
    cost : numpy.ndarray, shape (H, W), optional
        Cost per unit length of each cell (default 1 everywhere).

    Returns
    -------
    scipy.sparse.csr_matrix, shape (H * W, H * W)
        Edge weights, each undirected edge stored once (search with ``directed=False``).
    """
    from scipy.sparse import coo_matrix

    ok = np.asarray(passable, bool)
    H, W = ok.shape
    flat = np.arange(H * W).reshape(H, W)
    rows, cols, w = [], [], []
    for dr, dc in ((0, 1), (1, 0), (1, 1), (1, -1)):
        lo, hi = max(0, -dc), W - max(0, dc)
        both = ok[0:H - dr, lo:hi] & ok[dr:H, lo + dc:hi + dc]
        if dr and dc:  # no corner cutting: both side cells must be passable
            both &= ok[dr:H, lo:hi] & ok[0:H - dr, lo + dc:hi + dc]
        length = np.sqrt(2.0) if dr and dc else 1.0
        rows.append(flat[0:H - dr, lo:hi][both])
        cols.append(flat[dr:H, lo + dc:hi + dc][both])
        if cost is None:
            w.append(np.full(int(both.sum()), length))
        else:
            w.append(length * 0.5 * (cost[0:H - dr, lo:hi][both] + cost[dr:H, lo + dc:hi + dc][both]))
    return coo_matrix((np.concatenate(w), (np.concatenate(rows), np.concatenate(cols))), shape=(H * W, H * W)).tocsr()

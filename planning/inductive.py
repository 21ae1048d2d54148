"""The inductive term's reachability (Eq. 9): backward breadth-first search from preferred
states over transitions believed possible (probability above a threshold), up to a depth.

``goal_distances`` returns, per state, the number of believed-possible steps to the nearest
preferred state, or ``UNREACHABLE`` when that is beyond the depth (or there is no goal). It
works on edge lists (``B.edges(threshold, n)`` of a transition factor), so sparse transitions
with thousands of states cost O(edges x depth).
``reachability_matrix`` gives the same information in the layout of pymdp's
``generate_I_matrix`` (row ``i``: states that can reach a goal within ``i`` steps).
"""

from __future__ import annotations

import numpy as np

UNREACHABLE = np.iinfo(np.int64).max // 2


def goal_distances(
    src: np.ndarray, dst: np.ndarray, goal: np.ndarray, n: int, depth: int
) -> np.ndarray:
    """Steps from every state to the nearest goal state along edges ``src -> dst``; states
    more than ``depth`` steps away (or with no goal at all) get ``UNREACHABLE``."""
    dist = np.full(n, UNREACHABLE, dtype=np.int64)
    goal = np.asarray(goal)
    if goal.dtype == bool:
        goal = np.flatnonzero(goal[:n])
    if goal.size == 0:
        return dist
    dist[goal] = 0
    frontier = np.zeros(n, dtype=bool)
    frontier[goal] = True
    for d in range(1, depth + 1):
        preds = src[frontier[dst]]
        preds = preds[dist[preds] == UNREACHABLE]
        if preds.size == 0:
            break
        dist[preds] = d
        frontier[:] = False
        frontier[preds] = True
    return dist


def reachability_matrix(dist: np.ndarray, depth: int) -> np.ndarray:
    """``I[i, s] = 1`` when state ``s`` reaches a goal within ``i`` steps (``i < depth``)."""
    return (dist[None, :] <= np.arange(depth)[:, None]).astype(float)


def closer_probability(qs: np.ndarray, dist_next: np.ndarray, dist_prev: np.ndarray, depth: int) -> np.ndarray:
    """Per candidate ``k``: ``sum_s qs[k, s] [d(s) < d_prev[k] or d(s) = 0]``, zero for
    candidates whose anchor state is beyond the horizon (``d_prev > depth``)."""
    good = (dist_next[None, :] < dist_prev[:, None]) | (dist_next[None, :] == 0)
    val = (qs * good).sum(axis=1)
    return np.where(dist_prev <= depth, val, 0.0)

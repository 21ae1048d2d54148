"""What an exploring agent still believes it can reach: states it predicts (created by map
expansion, Eq. 7) but has never visited, connected to where it stands through transitions it
believes possible (Eq. 9: probability above the inductive threshold)."""

from __future__ import annotations

from collections import deque

import numpy as np


def reachable_mask(succ, prob, start: int, n: int, threshold: float = 0.5) -> np.ndarray:
    """States reachable from ``start`` over transitions believed possible (``prob > threshold``)
    in the sparse padded successor lists ``succ``/``prob`` (shape (capacity, actions, slots));
    breadth-first over the first ``n`` states."""
    succ, prob = np.asarray(succ), np.asarray(prob)
    seen = np.zeros(n, dtype=bool)
    if not 0 <= start < n:
        return seen
    seen[start] = True
    todo = deque([start])
    while todo:
        s = todo.popleft()
        for t in np.unique(succ[s][(prob[s] > threshold) & (succ[s] >= 0)]):
            t = int(t)
            if t < n and not seen[t]:
                seen[t] = True
                todo.append(t)
    return seen


def unvisited_reachable(agent) -> int:
    """Number of states ``agent`` predicts and believes reachable from its current state but has
    never visited (0 before its first decision)."""
    if agent.model is None or agent.last is None:
        return 0
    n = agent.num_states
    B = agent.model.B[0]
    mask = reachable_mask(B.succ, B.prob, int(agent.last.state), n, agent.cfg.inductive_threshold)
    return int((mask & ~agent.visited()).sum())

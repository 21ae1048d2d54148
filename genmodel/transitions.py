"""Sparse transition storage for topological maps.

``succ[s, u, k]`` is the k-th possible successor of state ``s`` under control ``u`` and
``prob[s, u, k]`` its probability; unused slots point at ``s`` with probability 0. Each node of a
topological map has a handful of neighbours, so predictions cost O(states x slots), not
O(states^2), and 10,000 states with 13 controls take a few MB.
"""

from __future__ import annotations

import numpy as np


class SparseTransitions:
    """Growable sparse B for one factor, with optional Dirichlet counts of the same layout."""

    def __init__(self, succ: np.ndarray, prob: np.ndarray, counts: np.ndarray | None = None):
        self.succ = np.asarray(succ, dtype=np.int64)
        self.prob = np.asarray(prob, dtype=float)
        self.counts = None if counts is None else np.asarray(counts, dtype=float)

    # -- shape ---------------------------------------------------------------------------
    @property
    def capacity(self) -> int:
        return self.succ.shape[0]

    @property
    def num_controls(self) -> int:
        return self.succ.shape[1]

    @property
    def slots(self) -> int:
        return self.succ.shape[2]

    @classmethod
    def empty(cls, capacity: int, num_controls: int, slots: int = 4, with_counts: bool = True):
        """All states self-looping under every control (an untried move leaves you in place)."""
        succ = np.broadcast_to(np.arange(capacity)[:, None, None], (capacity, num_controls, slots))
        prob = np.zeros((capacity, num_controls, slots))
        prob[:, :, 0] = 1.0
        counts = prob.copy() if with_counts else None
        return cls(succ.copy(), prob, counts)

    @classmethod
    def from_dense(cls, B: np.ndarray, slots: int | None = None, counts: np.ndarray | None = None):
        """Convert a dense ``(n, n, u)`` array (and counts of the same shape)."""
        B = np.asarray(B, dtype=float)
        n, _, u = B.shape
        nnz = (B > 0) if counts is None else (np.asarray(counts) > 0) | (B > 0)
        k = max(1, int(nnz.sum(axis=0).max())) if slots is None else slots
        out = cls.empty(n, u, k, with_counts=counts is not None)
        out.prob[:] = 0.0
        if out.counts is not None:
            out.counts[:] = 0.0
        for s in range(n):
            for a in range(u):
                idx = np.flatnonzero(nnz[:, s, a])
                out.succ[s, a, : len(idx)] = idx
                out.prob[s, a, : len(idx)] = B[idx, s, a]
                if counts is not None:
                    out.counts[s, a, : len(idx)] = np.asarray(counts)[idx, s, a]
        return out

    def to_dense(self, n: int | None = None) -> np.ndarray:
        """Dense ``(n, n, u)`` copy of the first ``n`` states (tests, pymdp export)."""
        n = self.capacity if n is None else n
        u = self.num_controls
        out = np.zeros((n, n, u))
        for a in range(u):
            s_idx = np.repeat(np.arange(n), self.slots)
            np.add.at(out[:, :, a], (self.succ[:n, a].ravel(), s_idx), self.prob[:n, a].ravel())
        return out

    def counts_dense(self, n: int | None = None) -> np.ndarray:
        n = self.capacity if n is None else n
        out = np.zeros((n, n, self.num_controls))
        if self.counts is None:
            return out
        for a in range(self.num_controls):
            s_idx = np.repeat(np.arange(n), self.slots)
            np.add.at(out[:, :, a], (self.succ[:n, a].ravel(), s_idx), self.counts[:n, a].ravel())
        return out

    # -- maths ---------------------------------------------------------------------------
    def predict(self, q: np.ndarray, u: int) -> np.ndarray:
        """Predictive distribution ``sum_s B[:, s, u] q[s]`` (length of ``q``)."""
        n = q.shape[0]
        w = (q[:, None] * self.prob[:n, u]).ravel()
        return np.bincount(self.succ[:n, u].ravel(), weights=w, minlength=n)[:n]

    def column(self, s: int, u: int, n: int) -> np.ndarray:
        out = np.zeros(n)
        np.add.at(out, self.succ[s, u], self.prob[s, u])
        return out

    # -- growth and learning -------------------------------------------------------------
    def grow(self, capacity: int) -> None:
        """Reallocate to a larger capacity, keeping every entry and count."""
        old = self.capacity
        new = SparseTransitions.empty(capacity, self.num_controls, self.slots, self.counts is not None)
        new.succ[:old] = self.succ
        new.prob[:old] = self.prob
        if self.counts is not None:
            new.counts[:old] = self.counts
        self.succ, self.prob, self.counts = new.succ, new.prob, new.counts

    def _widen(self) -> None:
        """Double the number of successor slots (rare: a node gained many neighbours)."""
        cap, u, k = self.succ.shape
        succ = np.empty((cap, u, 2 * k), dtype=np.int64)
        succ[:, :, :k] = self.succ
        succ[:, :, k:] = np.arange(cap)[:, None, None]
        prob = np.zeros((cap, u, 2 * k))
        prob[:, :, :k] = self.prob
        self.succ, self.prob = succ, prob
        if self.counts is not None:
            counts = np.zeros((cap, u, 2 * k))
            counts[:, :, :k] = self.counts
            self.counts = counts

    def slot_of(self, s: int, u: int, target: int, create: bool = True) -> int:
        """Slot holding ``target`` in column ``(s, u)``; claims a free slot when ``create``."""
        used = self.prob[s, u] > 0
        if self.counts is not None:
            used |= self.counts[s, u] > 0
        hit = np.flatnonzero(used & (self.succ[s, u] == target))
        if hit.size:
            return int(hit[0])
        if not create:
            return -1
        free = np.flatnonzero(~used)
        if free.size == 0:
            self._widen()
            free = np.array([self.slots // 2])
        k = int(free[0])
        self.succ[s, u, k] = target
        return k

    def renormalise_column(self, s: int, u: int) -> None:
        """Set ``prob[s, u]`` to the normalised counts of that column."""
        c = self.counts[s, u]
        total = c.sum()
        if total > 0:
            self.prob[s, u] = c / total

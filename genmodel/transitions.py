"""Transition factors that own their Dirichlet counts: dense and sparse, same operations.

Both types hold ``B`` for one factor at a reserved capacity, with optional counts, and offer
the same operations: ``predict`` (one step of a belief), ``column``, ``to_dense`` /
``counts_dense`` (live part), ``edges`` (believed-possible moves), ``add_state`` (a new state
that stays put), ``grow`` (a larger capacity) and ``learn`` (a Dirichlet update of one column,
renormalised).

:class:`DenseTransitions` stores ``prob[next, current, control]`` (pymdp layout).
:class:`SparseTransitions` stores padded successor lists: ``succ[s, u, k]`` is the k-th
possible successor of state ``s`` under control ``u`` and ``prob[s, u, k]`` its probability;
unused slots point at ``s`` with probability 0. Each node of a topological map has a handful of
neighbours, so predictions cost O(states x slots), not O(states^2), and 10,000 states with 13
controls take a few MB.
"""

from __future__ import annotations

import numpy as np


class DenseTransitions:
    """Dense ``prob[next, current, control]`` at capacity, with optional counts of the same shape."""

    def __init__(self, prob: np.ndarray, counts: np.ndarray | None = None):
        self.prob = np.asarray(prob, dtype=float)
        self.counts = None if counts is None else np.asarray(counts, dtype=float)

    @property
    def capacity(self) -> int:
        return self.prob.shape[0]

    @property
    def num_controls(self) -> int:
        return self.prob.shape[2]

    def predict(self, q: np.ndarray, u: int) -> np.ndarray:
        n = q.shape[0]
        return self.prob[:n, :n, u] @ q

    def column(self, s: int, u: int, n: int) -> np.ndarray:
        return self.prob[:n, s, u].copy()

    def to_dense(self, n: int | None = None) -> np.ndarray:
        """The live ``(n, n, u)`` block (a view)."""
        n = self.capacity if n is None else n
        return self.prob[:n, :n]

    def control_dense(self, u: int, n: int) -> np.ndarray:
        """The live ``B[:, :, u]`` (next, current) block (a view)."""
        return self.prob[:n, :n, u]

    def counts_dense(self, n: int | None = None) -> np.ndarray | None:
        n = self.capacity if n is None else n
        return None if self.counts is None else self.counts[:n, :n]

    def edges(self, threshold: float, n: int) -> tuple[np.ndarray, np.ndarray]:
        """``(src, dst)`` pairs with ``B[dst, src, u] > threshold`` for some control (no self loops)."""
        adj = (self.prob[:n, :n] > threshold).any(axis=2)
        np.fill_diagonal(adj, False)
        dst, src = np.nonzero(adj)
        return src, dst

    def control_edges(self, u: int, n: int, min_prob: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(src, dst, prob)`` of the moves under control ``u`` with probability >= ``min_prob``
        (no self loops)."""
        dst, src = np.nonzero(self.prob[:n, :n, u] >= min_prob)
        keep = src != dst
        return src[keep], dst[keep], self.prob[dst[keep], src[keep], u]

    def learn_soft(self, q_next: np.ndarray, q_prev: np.ndarray, u: int, lr: float, n: int,
                   floor: float = 1e-3) -> None:
        """Eq. (8) for transitions under beliefs: ``counts[:, :, u] += lr * q_next (x) q_prev``
        (touched counts floored at ``floor``), then the touched columns renormalised."""
        if self.counts is None:
            raise ValueError("these transitions have no Dirichlet counts to learn")
        outer = lr * np.outer(q_next[:n], q_prev[:n])
        block = self.counts[:n, :n, u] + outer
        block = np.where(outer > 0, np.maximum(block, floor), block)
        self.counts[:n, :n, u] = block
        cols = np.flatnonzero(q_prev[:n] > 0)
        self.prob[:n, cols, u] = block[:, cols] / block[:, cols].sum(axis=0, keepdims=True)

    def add_state(self, s: int, prior_count: float) -> None:
        """State ``s`` stays put under every control (counts ``prior_count`` on staying)."""
        self.prob[:, s, :] = 0.0
        self.prob[s, s, :] = 1.0
        if self.counts is not None:
            self.counts[:, s, :] = 0.0
            self.counts[s, s, :] = prior_count

    def grow(self, capacity: int) -> None:
        old, u = self.capacity, self.num_controls
        prob = np.zeros((capacity, capacity, u))
        prob[:old, :old] = self.prob
        prob[np.arange(old, capacity), np.arange(old, capacity), :] = 1.0
        self.prob = prob
        if self.counts is not None:
            counts = np.zeros((capacity, capacity, u))
            counts[:old, :old] = self.counts
            self.counts = counts

    def learn(self, s: int, u: int, target: int, lr: float, n: int, floor: float, max_concentration: float) -> None:
        """``counts[target, s, u] += lr`` (floored); a negative ``lr`` moves the mass to staying;
        the column is capped at ``max_concentration`` and renormalised (live states ``n``)."""
        c = self.counts
        if lr < 0 and c[target, s, u] <= 0:
            return  # nothing believed to remove
        c[target, s, u] = max(c[target, s, u] + lr, floor)
        if lr < 0:
            c[s, s, u] += -lr
        col = c[:n, s, u]
        total = col.sum()
        if total > max_concentration:
            col *= max_concentration / total
            total = max_concentration
        self.prob[:n, s, u] = col / total


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
        return np.stack([self.control_dense(a, n) for a in range(self.num_controls)], axis=2)

    def control_dense(self, u: int, n: int) -> np.ndarray:
        """Dense ``(n, n)`` ``B[:, :, u]`` (next, current) of the first ``n`` states."""
        out = np.zeros((n, n))
        np.add.at(out, (self.succ[:n, u].ravel(), np.repeat(np.arange(n), self.slots)), self.prob[:n, u].ravel())
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

    def edges(self, threshold: float, n: int) -> tuple[np.ndarray, np.ndarray]:
        """``(src, dst)`` pairs with probability above ``threshold`` (no self loops)."""
        s = self.succ[:n]
        ok = (self.prob[:n] > threshold) & (s != np.arange(n)[:, None, None])
        src = np.broadcast_to(np.arange(n)[:, None, None], s.shape)[ok]
        return src, s[ok]

    def control_edges(self, u: int, n: int, min_prob: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """As :meth:`DenseTransitions.control_edges`."""
        src = np.repeat(np.arange(n), self.slots)
        dst, prob = self.succ[:n, u].ravel(), self.prob[:n, u].ravel()
        keep = (prob >= min_prob) & (src != dst)
        return src[keep], dst[keep], prob[keep]

    def add_state(self, s: int, prior_count: float) -> None:
        """State ``s`` stays put under every control (counts ``prior_count`` on staying)."""
        self.succ[s] = s
        self.prob[s] = 0.0
        self.prob[s, :, 0] = 1.0
        if self.counts is not None:
            self.counts[s] = 0.0
            self.counts[s, :, 0] = prior_count

    def learn(self, s: int, u: int, target: int, lr: float, n: int, floor: float, max_concentration: float) -> None:
        """As :meth:`DenseTransitions.learn`, on the slot of ``target`` (claimed if new)."""
        if lr < 0 and self.slot_of(s, u, target, create=False) < 0:
            return  # nothing believed to remove
        k = self.slot_of(s, u, target)
        self.counts[s, u, k] = max(self.counts[s, u, k] + lr, floor)
        if lr < 0:
            k_stay = self.slot_of(s, u, s)  # may widen the arrays: index them afterwards
            self.counts[s, u, k_stay] += -lr
        total = self.counts[s, u].sum()
        if total > max_concentration:
            self.counts[s, u] *= max_concentration / total
        self.renormalise_column(s, u)

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

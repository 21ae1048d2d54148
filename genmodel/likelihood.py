"""Sparse, growable observation likelihood for a modality that depends on one factor.

Column ``s`` of ``A`` is the mean of a Dirichlet whose counts are a *symmetric prior* of total
concentration ``prior[s]`` spread evenly over the live outcomes, plus *learned counts* on the
few outcomes that were ever observed at ``s``::

    pA[o, s] = prior[s] / num_obs + learned[o, s]
    A[o, s]  = pA[o, s] / (prior[s] + learned_total[s])

Nothing is stored per (outcome, state) pair except the learned counts, in ``slots`` per column
(widened when a column needs more). So a new outcome or a new state costs O(1) amortised (a
column's prior mass stays ``prior[s]`` however many outcomes exist, and every column stays
normalised without being touched), memory is O(states x slots), and the statistics planning
needs (column entropies, novelty, the predicted outcome distribution of a few states) cost
O(slots) per state, independent of the size of the map.

Rows (``A[o, :]``, the evidence of an outcome) are assembled from the per-outcome list of the
states that learned it.
"""

from __future__ import annotations

import numpy as np
from scipy.special import digamma

EPS = float(np.finfo(float).eps)
SUPPORT_CUTOFF = 1e-12  # belief mass below which a learning update leaves a column alone


def _xlogx(x: np.ndarray) -> np.ndarray:
    return x * np.log(np.maximum(x, EPS))


def _novelty(a: np.ndarray, a0: np.ndarray) -> np.ndarray:
    """Parameter information-gain weight of a Dirichlet entry (see ``planning.efe.novelty_weights``)."""
    a = np.maximum(a, EPS)
    a0 = np.maximum(a0, EPS)
    return np.log(a0) - np.log(a) + digamma(a + 1.0) - digamma(a0 + 1.0)


class SparseLikelihood:
    """``A`` and its Dirichlet counts for one modality over one growable factor (module docstring)."""

    def __init__(self, num_obs: int, num_states: int, capacity: int, slots: int = 4):
        if num_obs < 1 or num_states < 0 or capacity < max(1, num_states) or slots < 1:
            raise ValueError("SparseLikelihood needs num_obs >= 1, 0 <= num_states <= capacity, slots >= 1")
        self.num_obs = int(num_obs)
        self.num_states = int(num_states)
        self.prior = np.zeros(capacity)
        self.learned_total = np.zeros(capacity)
        self.obs = np.full((capacity, slots), -1, dtype=np.int64)  # learned outcome per slot (-1: free)
        self.cnt = np.zeros((capacity, slots))
        self.rows: list[list[int]] = [[] for _ in range(num_obs)]  # states that learned each outcome
        self.reallocations = 0

    # -- construction ---------------------------------------------------------------------
    @classmethod
    def from_counts(cls, prior, learned, capacity: int | None = None) -> SparseLikelihood:
        """From per-column prior concentrations ``prior`` (n,) and learned counts given as a
        dense (outcomes, n) array or as ``(outcomes, states, counts)`` triples with ``num_obs``."""
        prior = np.asarray(prior, dtype=float)
        n = prior.size
        if isinstance(learned, tuple):
            num_obs, o_idx, s_idx, c = learned
        else:
            dense = np.asarray(learned, dtype=float)
            num_obs = dense.shape[0]
            o_idx, s_idx = np.nonzero(dense)
            c = dense[o_idx, s_idx]
        out = cls(int(num_obs), n, max(1, n) if capacity is None else capacity)
        out.prior[:n] = prior
        for o, s, v in zip(np.asarray(o_idx), np.asarray(s_idx), np.asarray(c, dtype=float), strict=True):
            out._add(int(o), int(s), float(v))
        return out

    # -- shape ------------------------------------------------------------------------------
    @property
    def capacity(self) -> int:
        return self.prior.shape[0]

    @property
    def slots(self) -> int:
        return self.obs.shape[1]

    @property
    def nbytes(self) -> int:
        return self.prior.nbytes + self.learned_total.nbytes + self.obs.nbytes + self.cnt.nbytes

    def total(self, states=None) -> np.ndarray:
        """Column concentrations ``sum_o pA[o, s]``."""
        s = slice(0, self.num_states) if states is None else states
        return self.prior[s] + self.learned_total[s]

    # -- growth -----------------------------------------------------------------------------
    def add_state(self, concentration: float) -> int:
        """A new column: the symmetric prior of total ``concentration``, nothing learned."""
        s = self.num_states
        if s == self.capacity:
            self._reallocate(2 * max(1, s), self.slots)
        self.num_states = s + 1
        self.prior[s] = concentration
        self.learned_total[s] = 0.0
        self.obs[s] = -1
        self.cnt[s] = 0.0
        return s

    def add_observation(self) -> int:
        """A new outcome; every column spreads its prior over one more outcome (O(1))."""
        self.rows.append([])
        self.num_obs += 1
        return self.num_obs - 1

    def _reallocate(self, capacity: int, slots: int) -> None:
        self.reallocations += 1
        old_cap, old_slots = self.obs.shape
        obs = np.full((capacity, slots), -1, dtype=np.int64)
        cnt = np.zeros((capacity, slots))
        obs[:old_cap, :old_slots] = self.obs
        cnt[:old_cap, :old_slots] = self.cnt
        self.obs, self.cnt = obs, cnt
        if capacity != old_cap:
            self.prior = np.concatenate([self.prior, np.zeros(capacity - old_cap)])
            self.learned_total = np.concatenate([self.learned_total, np.zeros(capacity - old_cap)])

    # -- learning ---------------------------------------------------------------------------
    def _add(self, o: int, s: int, value: float) -> None:
        row = self.obs[s]
        hit = np.flatnonzero(row == o)
        if hit.size:
            k = int(hit[0])
        else:
            free = np.flatnonzero(row < 0)
            if free.size == 0:
                self._reallocate(self.capacity, 2 * self.slots)
                k = self.slots // 2
            else:
                k = int(free[0])
            self.obs[s, k] = o
            self.rows[o].append(s)
        self.cnt[s, k] += value
        self.learned_total[s] += value

    def learn(self, obs: int, q: np.ndarray, lr: float = 1.0) -> None:
        """Dirichlet update ``pA[obs, s] += lr * q[s]`` for the states ``q`` reaches (mass above
        ``SUPPORT_CUTOFF``: a smaller update changes no count by more than 1e-12)."""
        q = np.asarray(q, dtype=float)[: self.num_states]
        if lr <= 0:
            raise ValueError(f"learning rate must be positive, got {lr}")
        for s in np.flatnonzero(q > SUPPORT_CUTOFF):
            self._add(int(obs), int(s), lr * float(q[s]))

    # -- entries ----------------------------------------------------------------------------
    def learned(self, o: int, states: np.ndarray) -> np.ndarray:
        """Learned counts of outcome ``o`` at ``states``."""
        states = np.asarray(states, dtype=np.int64)
        return ((self.obs[states] == o) * self.cnt[states]).sum(axis=1)

    def counts_row(self, o: int) -> np.ndarray:
        """``pA[o, :]`` over the live states."""
        n = self.num_states
        out = self.prior[:n] / self.num_obs
        idx = np.asarray(self.rows[o], dtype=np.int64)
        if idx.size:
            out[idx] += self.learned(o, idx)
        return out

    def row(self, o: int) -> np.ndarray:
        """``A[o, :]`` over the live states: the evidence of outcome ``o``."""
        return self.counts_row(o) / self.total()

    def expected_row(self, p: np.ndarray) -> np.ndarray:
        """``sum_o p[o] A[o, :]`` for a distribution ``p`` over the live outcomes."""
        n = self.num_states
        p = np.asarray(p, dtype=float)[: self.num_obs]
        obs = self.obs[:n]
        learned = (np.where(obs >= 0, p[np.maximum(obs, 0)], 0.0) * self.cnt[:n]).sum(axis=1)
        return (p.sum() * self.prior[:n] / self.num_obs + learned) / self.total()

    def column(self, s: int) -> np.ndarray:
        """``A[:, s]`` over the live outcomes (dense: O(outcomes))."""
        out = np.full(self.num_obs, self.prior[s] / self.num_obs)
        ok = self.obs[s] >= 0
        np.add.at(out, self.obs[s][ok], self.cnt[s][ok])
        return out / self.total([s])[0]

    def to_dense(self) -> np.ndarray:
        """Dense ``A`` (outcomes x states) of the live part (tests, export, small models)."""
        return self.counts_dense() / np.maximum(self.total(), EPS)

    def counts_dense(self) -> np.ndarray:
        n = self.num_states
        out = np.tile(self.prior[:n] / self.num_obs, (self.num_obs, 1))
        s_idx, k_idx = np.nonzero(self.obs[:n] >= 0)
        np.add.at(out, (self.obs[s_idx, k_idx], s_idx), self.cnt[s_idx, k_idx])
        return out

    def taught(self, threshold: float) -> np.ndarray:
        """Mask of live states whose largest count exceeds ``threshold``."""
        n = self.num_states
        top = np.max(self.cnt[:n], axis=1, initial=0.0)
        return self.prior[:n] / self.num_obs + top > threshold

    def outcomes_above(self, s: int, threshold: float) -> np.ndarray:
        """Outcomes ``o`` with ``A[o, s] >= threshold`` (sorted; O(slots) unless the prior alone
        reaches the threshold)."""
        T = self.total([s])[0]
        bg = self.prior[s] / self.num_obs
        if bg / T >= threshold:
            return np.flatnonzero(self.column(s) >= threshold)
        ok = (self.obs[s] >= 0) & ((bg + self.cnt[s]) / T >= threshold)
        return np.sort(self.obs[s][ok])

    def most_likely(self) -> np.ndarray:
        """Most likely outcome per live state (-1 where nothing was learned)."""
        n = self.num_states
        k = np.argmax(self.cnt[:n], axis=1)
        best = self.obs[:n][np.arange(n), k]
        return np.where(self.cnt[:n][np.arange(n), k] > 0, best, -1)

    # -- planning statistics (O(slots) per state) ------------------------------------------
    def column_stats(self, states: np.ndarray, novelty: bool = True):
        """Per state in ``states``: entropy of its column, and the novelty weight of its
        background (unlearned) outcomes and of each learned slot (zeros when ``novelty`` is
        False). Returns ``(H, w_bg, w_slots)`` with shapes (U,), (U,), (U, slots)."""
        states = np.asarray(states, dtype=np.int64)
        n_o = self.num_obs
        T = self.total(states)
        bg = self.prior[states] / n_o
        valid = self.obs[states] >= 0
        a = bg[:, None] + self.cnt[states]
        k = valid.sum(axis=1)
        H = -((n_o - k) * _xlogx(bg / T) + np.where(valid, _xlogx(a / T[:, None]), 0.0).sum(axis=1))
        if not novelty:
            return H, np.zeros_like(H), np.zeros(a.shape)
        w_bg = np.where(bg > 0, _novelty(bg, T), 0.0)
        w_slots = np.where(valid, _novelty(a, T[:, None]), 0.0)
        return H, w_bg, w_slots

    def mixture(self, states: np.ndarray, qs: np.ndarray):
        """Predicted outcome distributions of ``K`` beliefs ``qs`` (K, U) over ``states`` (U,),
        compressed: ``(bg, outcomes, values)`` with ``bg`` (K,) the probability of every outcome
        no state in ``states`` learned, ``outcomes`` (W,) the learned ones and ``values`` (K, W)
        their probabilities. ``num_obs - W`` outcomes share ``bg``."""
        states = np.asarray(states, dtype=np.int64)
        T = self.total(states)
        bg = qs @ (self.prior[states] / self.num_obs / T)
        obs = self.obs[states]
        valid = obs >= 0
        outcomes, inv = np.unique(obs[valid], return_inverse=True)
        U, W = states.size, outcomes.size
        contrib = np.zeros((U, W))
        rows = np.nonzero(valid)[0]
        np.add.at(contrib, (rows, inv), (self.cnt[states] / T[:, None])[valid])
        return bg, outcomes, bg[:, None] + qs @ contrib

    def slot_outcome_index(self, states: np.ndarray, outcomes: np.ndarray) -> np.ndarray:
        """For each (state, slot), the position of its outcome in ``outcomes`` (-1: free slot)."""
        obs = self.obs[np.asarray(states, dtype=np.int64)]
        pos = np.searchsorted(outcomes, np.maximum(obs, 0))
        pos = np.minimum(pos, max(outcomes.size - 1, 0))
        ok = (obs >= 0) & (outcomes.size > 0)
        if outcomes.size:
            ok &= outcomes[pos] == obs
        return np.where(ok, pos, -1)

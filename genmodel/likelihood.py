"""Likelihood factors that own their Dirichlet counts: dense and sparse, same operations.

Both types hold ``A`` for one modality with its counts and offer: ``row`` / ``counts_row`` (the
evidence of one outcome over the live states), ``expected_row`` (of a distribution over
outcomes), ``to_dense`` / ``counts_dense``, ``learn`` (the Dirichlet update of Eq. 8),
``add_state`` / ``add_observation`` / ``grow_*`` (growth into reserved room), and for
single-factor modalities the planning statistics ``column_stats`` and ``mixture``.

:class:`DenseLikelihood` stores ``A[o, s_1, ..., s_k]`` at capacity (pymdp layout).

:class:`SparseLikelihood`, for a modality over one growable factor, stores counts only:
column ``s`` of ``A`` is the mean of a Dirichlet whose counts are a *symmetric prior* of total
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

from .capacity import pad_axis
from .dirichlet import as_distribution, normalise_counts, update_pA
from .dirichlet import novelty as dirichlet_novelty
from .numerics import LOG_FLOOR, xlogx
from .spec import SpecError

EPS = LOG_FLOOR  # the shared log floor (cogmap.genmodel.numerics)
SUPPORT_CUTOFF = 1e-12  # belief mass below which a learning update leaves a column alone


class DenseLikelihood:
    """``A`` (outcomes x states of each dependency) at capacity, with optional counts."""

    def __init__(self, prob: np.ndarray, counts: np.ndarray | None, num_obs: int, num_states: tuple[int, ...]):
        self.prob = np.asarray(prob, dtype=float)
        self.counts = None if counts is None else np.asarray(counts, dtype=float)
        self.num_obs = int(num_obs)
        self.num_states = tuple(int(n) for n in num_states)

    @property
    def has_counts(self) -> bool:
        return self.counts is not None

    @property
    def obs_capacity(self) -> int:
        return self.prob.shape[0]

    def _live(self) -> tuple[slice, ...]:
        return (slice(0, self.num_obs),) + tuple(slice(0, n) for n in self.num_states)

    def to_dense(self) -> np.ndarray:
        """The live block (a view)."""
        return self.prob[self._live()]

    def counts_dense(self) -> np.ndarray | None:
        return None if self.counts is None else self.counts[self._live()]

    def row(self, o: int) -> np.ndarray:
        return self.prob[(o,) + self._live()[1:]]

    def counts_row(self, o: int) -> np.ndarray:
        if self.counts is None:
            raise SpecError("this likelihood has no Dirichlet counts")
        return self.counts[(o,) + self._live()[1:]]

    def expected_row(self, p: np.ndarray) -> np.ndarray:
        return np.tensordot(np.asarray(p, dtype=float)[: self.num_obs], self.to_dense(), axes=(0, 0))

    def column(self, s: int) -> np.ndarray:
        return self.prob[: self.num_obs, s].copy()

    def learn(self, obs, qs: list[np.ndarray], lr: float = 1.0) -> None:
        """Eq. (8): ``pA += lr * o (x) q(deps)``, then ``A`` renormalised where touched."""
        if self.counts is None:
            raise SpecError("this likelihood has no Dirichlet counts to learn")
        n_o = self.num_obs
        if len(qs) == 1:  # touch only the columns the belief reaches: O(outcomes x support)
            q = np.asarray(qs[0], dtype=float)
            cols = np.flatnonzero(q > 0)
            o = as_distribution(obs, n_o)
            block = self.counts[:n_o, cols] + lr * np.outer(o, q[cols])
            block = np.where(o[:, None] > 0, np.maximum(block, 1e-3), block)
            self.counts[:n_o, cols] = block
            self.prob[:n_o, cols] = normalise_counts(block)
            return
        live = self._live()
        new = update_pA(self.counts[live], obs, qs, lr)
        self.counts[live] = new
        self.prob[live] = normalise_counts(new)

    # -- growth -----------------------------------------------------------------------------
    def add_state(self, axis: int, count: float) -> None:
        """A new state on dependency ``axis``: its columns uniform over the live outcomes, with
        ``count`` Dirichlet counts per outcome."""
        s = self.num_states[axis]
        sizes = list(self.num_states)
        sizes[axis] = s + 1
        self.num_states = tuple(sizes)
        col = [slice(None)] * self.prob.ndim
        col[1 + axis] = s
        col = tuple(col)
        n_o = self.num_obs
        self.prob[col] = 0.0
        self.prob[col][:n_o] = 1.0 / max(1, n_o)
        if self.counts is not None:
            self.counts[col] = 0.0
            self.counts[col][:n_o] = count

    def add_observation(self, count: float) -> None:
        """A new outcome: every live column gains ``count`` for it and is renormalised from its
        counts (without counts it starts with probability 0 everywhere)."""
        o = self.num_obs
        self.num_obs = o + 1
        live = self._live()[1:]
        self.prob[(o,) + live] = 0.0
        if self.counts is not None:
            self.counts[(o,) + live] = count
            counts = self.counts[(slice(0, o + 1),) + live]
            self.prob[(slice(0, o + 1),) + live] = counts / counts.sum(axis=0, keepdims=True)

    def grow_states(self, axis: int, capacity: int) -> None:
        self.prob = pad_axis(self.prob, 1 + axis, capacity)
        if self.counts is not None:
            self.counts = pad_axis(self.counts, 1 + axis, capacity)

    def grow_obs(self, capacity: int) -> None:
        self.prob = pad_axis(self.prob, 0, capacity)
        if self.counts is not None:
            self.counts = pad_axis(self.counts, 0, capacity)

    # -- single-factor queries ------------------------------------------------------------
    def taught(self, threshold: float) -> np.ndarray:
        return self.counts_dense().max(axis=0) > threshold

    def most_likely(self) -> np.ndarray:
        return self.to_dense().argmax(axis=0)

    def outcomes_above(self, s: int, threshold: float) -> np.ndarray:
        return np.flatnonzero(self.column(s) >= threshold)

    def column_stats(self, states: np.ndarray, novelty: bool = True):
        """As :meth:`SparseLikelihood.column_stats`, with every outcome a "slot"."""
        states = np.asarray(states, dtype=np.int64)
        cols = self.prob[: self.num_obs, states]
        H = -xlogx(cols).sum(axis=0)
        zero = np.zeros(states.size)
        if not novelty or self.counts is None:
            return H, zero, np.zeros((states.size, self.num_obs))
        a = self.counts[: self.num_obs, states]
        w = np.where(a > 0, dirichlet_novelty(a, a.sum(axis=0, keepdims=True)), 0.0)
        return H, zero, w.T

    def mixture(self, states: np.ndarray, qs: np.ndarray):
        """As :meth:`SparseLikelihood.mixture`: every outcome is listed, none in the background."""
        values = qs @ self.prob[: self.num_obs, np.asarray(states, dtype=np.int64)].T
        return np.zeros(qs.shape[0]), np.arange(self.num_obs), values

    def scatter_slots(self, states: np.ndarray, outcomes: np.ndarray, per_slot: np.ndarray) -> np.ndarray:
        """As :meth:`SparseLikelihood.scatter_slots`: here slots are the outcomes themselves."""
        return per_slot


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
    has_counts = True

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
    def add_state(self, axis: int, count: float) -> int:
        """A new column with ``count`` prior counts per live outcome (total concentration
        ``count x num_obs``, spread over however many outcomes there will be), nothing learned."""
        if axis != 0:
            raise ValueError("a sparse likelihood depends on one factor (axis 0)")
        return self._add_column(count * self.num_obs)

    def _add_column(self, concentration: float) -> int:
        s = self.num_states
        if s == self.capacity:
            self._reallocate(2 * max(1, s), self.slots)
        self.num_states = s + 1
        self.prior[s] = concentration
        self.learned_total[s] = 0.0
        self.obs[s] = -1
        self.cnt[s] = 0.0
        return s

    def add_observation(self, count: float | None = None) -> int:
        """A new outcome; every column spreads its prior over one more outcome (O(1)). Columns
        keep their prior mass, so a per-outcome ``count`` does not apply."""
        if count is not None:
            raise SpecError("a sparse likelihood's columns keep their prior mass, spread over the "
                            "outcomes; add_observation takes no count")
        self.rows.append([])
        self.num_obs += 1
        return self.num_obs - 1

    def grow_states(self, axis: int, capacity: int) -> None:
        """Reserve room for ``capacity`` states (the model grows its factor)."""
        if capacity > self.capacity:
            self._reallocate(capacity, self.slots)

    def grow_obs(self, capacity: int) -> None:
        """Outcomes need no reserved room (nothing is stored per outcome and state)."""

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

    def learn(self, obs: int, qs: list[np.ndarray], lr: float = 1.0) -> None:
        """Dirichlet update ``pA[obs, s] += lr * q[s]`` for the states ``q = qs[0]`` reaches (mass
        above ``SUPPORT_CUTOFF``: a smaller update changes no count by more than 1e-12)."""
        if not isinstance(obs, int | np.integer):
            raise SpecError("a sparse likelihood learns from an outcome index")
        q = np.asarray(qs[0], dtype=float)[: self.num_states]
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
        H = -((n_o - k) * xlogx(bg / T) + np.where(valid, xlogx(a / T[:, None]), 0.0).sum(axis=1))
        if not novelty:
            return H, np.zeros_like(H), np.zeros(a.shape)
        w_bg = np.where(bg > 0, dirichlet_novelty(bg, T), 0.0)
        w_slots = np.where(valid, dirichlet_novelty(a, T[:, None]), 0.0)
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

    def scatter_slots(self, states: np.ndarray, outcomes: np.ndarray, per_slot: np.ndarray) -> np.ndarray:
        """``out[i, j]``: the value ``per_slot[i, k]`` of the slot of state ``states[i]`` holding
        outcome ``outcomes[j]`` (0 where that state learned nothing of it); ``outcomes`` sorted."""
        obs = self.obs[np.asarray(states, dtype=np.int64)]
        out = np.zeros((obs.shape[0], outcomes.size))
        rows, k = np.nonzero(obs >= 0)
        if rows.size:
            out[rows, np.searchsorted(outcomes, obs[rows, k])] = per_slot[rows, k]
        return out

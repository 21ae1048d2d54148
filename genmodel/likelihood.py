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
    """``A`` (outcomes x states of each dependency) at capacity, with optional Dirichlet counts.

    Parameters
    ----------
    prob : numpy.ndarray
        ``(obs_capacity, state_capacity_1, ..., state_capacity_k)`` float: ``A[o, s_1, ..., s_k]``
        in pymdp layout; the live block (first ``num_obs`` outcomes, first ``num_states[i]`` states
        of each dependency) has columns summing to 1.
    counts : numpy.ndarray or None
        Dirichlet counts ``pA``, same shape as ``prob``; None for a fixed likelihood.
    num_obs : int
        Number of live outcomes.
    num_states : tuple of int
        Number of live states of each dependency, in the order of the state axes.
    """

    def __init__(self, prob: np.ndarray, counts: np.ndarray | None, num_obs: int, num_states: tuple[int, ...]):
        self.prob = np.asarray(prob, dtype=float)
        self.counts = None if counts is None else np.asarray(counts, dtype=float)
        self.num_obs = int(num_obs)
        self.num_states = tuple(int(n) for n in num_states)

    @property
    def has_counts(self) -> bool:
        """Whether this likelihood holds Dirichlet counts (so it can learn)."""
        return self.counts is not None

    @property
    def obs_capacity(self) -> int:
        """Number of outcomes room is reserved for (axis 0 of ``prob``)."""
        return self.prob.shape[0]

    def _live(self) -> tuple[slice, ...]:
        return (slice(0, self.num_obs),) + tuple(slice(0, n) for n in self.num_states)

    def to_dense(self) -> np.ndarray:
        """The live block of ``A`` (a view, not a copy).

        Returns
        -------
        numpy.ndarray
            ``(num_obs, *num_states)`` float, columns sum to 1.
        """
        return self.prob[self._live()]

    def counts_dense(self) -> np.ndarray | None:
        """The live block of the Dirichlet counts (a view), or None without counts.

        Returns
        -------
        numpy.ndarray or None
            ``(num_obs, *num_states)`` float counts ``pA``.
        """
        return None if self.counts is None else self.counts[self._live()]

    def row(self, o: int) -> np.ndarray:
        """``A[o, ...]`` over the live states: the evidence of outcome ``o`` (a view).

        Parameters
        ----------
        o : int
            Outcome index, ``0 <= o < num_obs``.

        Returns
        -------
        numpy.ndarray
            ``num_states`` shaped float, the probability of ``o`` under each live state combination.
        """
        return self.prob[(o,) + self._live()[1:]]

    def counts_row(self, o: int) -> np.ndarray:
        """``pA[o, ...]`` over the live states (a view).

        Parameters
        ----------
        o : int
            Outcome index, ``0 <= o < num_obs``.

        Returns
        -------
        numpy.ndarray
            ``num_states`` shaped float Dirichlet counts.

        Raises
        ------
        SpecError
            If the likelihood has no Dirichlet counts.
        """
        if self.counts is None:
            raise SpecError("this likelihood has no Dirichlet counts")
        return self.counts[(o,) + self._live()[1:]]

    def expected_row(self, p: np.ndarray) -> np.ndarray:
        """``sum_o p[o] A[o, ...]`` for a distribution ``p`` over outcomes.

        Parameters
        ----------
        p : numpy.ndarray
            ``(n,)`` float with ``n >= num_obs``; only its first ``num_obs`` entries are used.

        Returns
        -------
        numpy.ndarray
            ``num_states`` shaped float, the expected evidence of each live state combination.
        """
        return np.tensordot(np.asarray(p, dtype=float)[: self.num_obs], self.to_dense(), axes=(0, 0))

    def column(self, s: int) -> np.ndarray:
        """A copy of ``A[:, s]`` over the live outcomes.

        Parameters
        ----------
        s : int
            State index on the first dependency.

        Returns
        -------
        numpy.ndarray
            ``(num_obs, ...)`` float; for a single-factor modality ``(num_obs,)``, sums to 1.
        """
        return self.prob[: self.num_obs, s].copy()

    def learn(self, obs, qs: list[np.ndarray], lr: float = 1.0) -> None:
        """Dirichlet update of the counts, ``pA += lr * o (x) q(deps)``, then ``A`` renormalised where touched.

        With one dependency only the columns the belief reaches (``q > 0``) are updated, and counts of
        the observed outcome are floored at 1e-3 there.

        Parameters
        ----------
        obs : int or numpy.ndarray
            Observed outcome index, or a ``(num_obs,)`` distribution over outcomes.
        qs : list of numpy.ndarray
            Posterior over each dependency, ``(num_states[i],)`` float, each summing to 1.
        lr : float, optional
            Learning rate (scales the added counts), default 1.

        Raises
        ------
        SpecError
            If the likelihood has no Dirichlet counts.

        Notes
        -----
        Eq. (8) of the AIMAPP paper.
        """
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
        """Add a state on dependency ``axis``: its columns uniform over the live outcomes.

        The new columns get ``count`` Dirichlet counts per live outcome (if the likelihood has counts).
        Room must already be reserved (see :meth:`grow_states`).

        Parameters
        ----------
        axis : int
            Which dependency (0-based, in the order of ``num_states``) gains a state.
        count : float
            Dirichlet count given to every live outcome in the new columns.
        """
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
        """Add an outcome: every live column gains ``count`` for it and is renormalised from its counts.

        Without counts the new outcome starts with probability 0 in every column. Room must already be
        reserved (see :meth:`grow_obs`).

        Parameters
        ----------
        count : float
            Dirichlet count of the new outcome in every live column.
        """
        o = self.num_obs
        self.num_obs = o + 1
        live = self._live()[1:]
        self.prob[(o,) + live] = 0.0
        if self.counts is not None:
            self.counts[(o,) + live] = count
            counts = self.counts[(slice(0, o + 1),) + live]
            self.prob[(slice(0, o + 1),) + live] = counts / counts.sum(axis=0, keepdims=True)

    def grow_states(self, axis: int, capacity: int) -> None:
        """Reserve room for ``capacity`` states on dependency ``axis`` (zero-padding ``prob`` and counts).

        Parameters
        ----------
        axis : int
            Which dependency (0-based).
        capacity : int
            New size of that state axis.
        """
        self.prob = pad_axis(self.prob, 1 + axis, capacity)
        if self.counts is not None:
            self.counts = pad_axis(self.counts, 1 + axis, capacity)

    def grow_obs(self, capacity: int) -> None:
        """Reserve room for ``capacity`` outcomes (zero-padding axis 0 of ``prob`` and counts).

        Parameters
        ----------
        capacity : int
            New size of the outcome axis.
        """
        self.prob = pad_axis(self.prob, 0, capacity)
        if self.counts is not None:
            self.counts = pad_axis(self.counts, 0, capacity)

    # -- single-factor queries ------------------------------------------------------------
    def taught(self, threshold: float) -> np.ndarray:
        """Mask of live states whose largest Dirichlet count exceeds ``threshold`` (single-factor modality).

        Parameters
        ----------
        threshold : float
            Count above which a state counts as taught.

        Returns
        -------
        numpy.ndarray
            ``(num_states,)`` bool.
        """
        return self.counts_dense().max(axis=0) > threshold

    def most_likely(self) -> np.ndarray:
        """Most likely outcome of each live state (single-factor modality).

        Returns
        -------
        numpy.ndarray
            ``(num_states,)`` int, ``argmax_o A[o, s]``.
        """
        return self.to_dense().argmax(axis=0)

    def outcomes_above(self, s: int, threshold: float) -> np.ndarray:
        """Outcomes ``o`` with ``A[o, s] >= threshold``.

        Parameters
        ----------
        s : int
            State index.
        threshold : float
            Probability threshold.

        Returns
        -------
        numpy.ndarray
            Sorted int outcome indices.
        """
        return np.flatnonzero(self.column(s) >= threshold)

    def column_stats(self, states: np.ndarray, novelty: bool = True):
        """Column entropies and novelty weights of ``states``, as :meth:`SparseLikelihood.column_stats`.

        Here every outcome is a "slot", so the background weight is always zero.

        Parameters
        ----------
        states : numpy.ndarray
            ``(U,)`` int state indices.
        novelty : bool, optional
            Whether to compute the novelty weights (zeros otherwise, and always zeros without counts).

        Returns
        -------
        H : numpy.ndarray
            ``(U,)`` float, entropy (nats) of each column ``A[:, s]``.
        w_bg : numpy.ndarray
            ``(U,)`` float zeros.
        w_slots : numpy.ndarray
            ``(U, num_obs)`` float novelty weight of each outcome at each state
            (:func:`cogmap.genmodel.dirichlet.novelty` of the counts; 0 where a count is 0).
        """
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
        """Predicted outcome distributions of ``K`` beliefs, as :meth:`SparseLikelihood.mixture`.

        Every outcome is listed; none is in the background.

        Parameters
        ----------
        states : numpy.ndarray
            ``(U,)`` int state indices.
        qs : numpy.ndarray
            ``(K, U)`` float, beliefs over ``states``.

        Returns
        -------
        bg : numpy.ndarray
            ``(K,)`` float zeros.
        outcomes : numpy.ndarray
            ``(num_obs,)`` int, ``arange(num_obs)``.
        values : numpy.ndarray
            ``(K, num_obs)`` float, ``qs @ A[:, states].T``.
        """
        values = qs @ self.prob[: self.num_obs, np.asarray(states, dtype=np.int64)].T
        return np.zeros(qs.shape[0]), np.arange(self.num_obs), values

    def scatter_slots(self, states: np.ndarray, outcomes: np.ndarray, per_slot: np.ndarray) -> np.ndarray:
        """As :meth:`SparseLikelihood.scatter_slots`; here the slots are the outcomes themselves.

        Parameters
        ----------
        states : numpy.ndarray
            ``(U,)`` int state indices (unused).
        outcomes : numpy.ndarray
            ``(num_obs,)`` int outcomes (unused).
        per_slot : numpy.ndarray
            ``(U, num_obs)`` float values per outcome.

        Returns
        -------
        numpy.ndarray
            ``per_slot`` itself.
        """
        return per_slot


class SparseLikelihood:
    """``A`` and its Dirichlet counts for one modality over one growable factor, stored sparsely.

    Column ``s`` is the mean of a Dirichlet with a symmetric prior of total concentration
    ``prior[s]`` spread over the live outcomes plus learned counts on a few outcomes, kept in
    ``slots`` per column (see the module docstring). The instance starts with no column learned and
    all priors 0; use :meth:`from_counts` or :meth:`add_state` to fill it.

    Parameters
    ----------
    num_obs : int
        Number of live outcomes, at least 1.
    num_states : int
        Number of live states, ``0 <= num_states <= capacity``.
    capacity : int
        Number of states room is reserved for (doubled automatically when full).
    slots : int, optional
        Learned outcomes stored per column before the table is widened, default 4.

    Raises
    ------
    ValueError
        If the sizes are inconsistent.
    """

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
        """Build from per-column prior concentrations and learned counts.

        Parameters
        ----------
        prior : array_like
            ``(n,)`` float, total prior concentration of each column.
        learned : numpy.ndarray or tuple
            Learned counts, either dense ``(num_obs, n)`` float or a tuple
            ``(num_obs, outcome_indices, state_indices, counts)``.
        capacity : int, optional
            State capacity; default ``max(1, n)``.

        Returns
        -------
        SparseLikelihood
            A likelihood with ``n`` live states.
        """
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
        """Number of states room is reserved for."""
        return self.prior.shape[0]

    @property
    def slots(self) -> int:
        """Number of learned outcomes stored per column before the table is widened."""
        return self.obs.shape[1]

    @property
    def nbytes(self) -> int:
        """Bytes held by the arrays (prior, totals, slot outcomes and slot counts)."""
        return self.prior.nbytes + self.learned_total.nbytes + self.obs.nbytes + self.cnt.nbytes

    def total(self, states=None) -> np.ndarray:
        """Column concentrations ``sum_o pA[o, s]`` (prior plus learned).

        Parameters
        ----------
        states : array_like or slice, optional
            Which columns; default all live states.

        Returns
        -------
        numpy.ndarray
            Float concentrations, one per selected state.
        """
        s = slice(0, self.num_states) if states is None else states
        return self.prior[s] + self.learned_total[s]

    # -- growth -----------------------------------------------------------------------------
    def add_state(self, axis: int, count: float) -> int:
        """Add a column with ``count`` prior counts per live outcome and nothing learned.

        Its total concentration is ``count * num_obs``, later spread over however many outcomes there
        are. Doubles the capacity when full.

        Parameters
        ----------
        axis : int
            Must be 0 (a sparse likelihood depends on one factor).
        count : float
            Prior count per live outcome.

        Returns
        -------
        int
            Index of the new state.

        Raises
        ------
        ValueError
            If ``axis`` is not 0.
        """
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
        """Add an outcome; every column spreads its prior over one more outcome (O(1)).

        Columns keep their prior mass, so a per-outcome count does not apply.

        Parameters
        ----------
        count : None, optional
            Must be None.

        Returns
        -------
        int
            Index of the new outcome.

        Raises
        ------
        SpecError
            If ``count`` is given.
        """
        if count is not None:
            raise SpecError("a sparse likelihood's columns keep their prior mass, spread over the "
                            "outcomes; add_observation takes no count")
        self.rows.append([])
        self.num_obs += 1
        return self.num_obs - 1

    def grow_states(self, axis: int, capacity: int) -> None:
        """Reserve room for ``capacity`` states (the model grows its factor).

        Parameters
        ----------
        axis : int
            Ignored (a sparse likelihood has one state axis).
        capacity : int
            New state capacity; nothing happens if it is not larger than the current one.
        """
        if capacity > self.capacity:
            self._reallocate(capacity, self.slots)

    def grow_obs(self, capacity: int) -> None:
        """Do nothing: outcomes need no reserved room (nothing is stored per outcome and state).

        Parameters
        ----------
        capacity : int
            Ignored.
        """

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
        """Dirichlet update ``pA[obs, s] += lr * q[s]`` for the states ``q = qs[0]`` reaches.

        Only states with mass above ``SUPPORT_CUTOFF`` (1e-12) are updated: a smaller update would change
        no count by more than 1e-12.

        Parameters
        ----------
        obs : int
            Observed outcome index.
        qs : list of numpy.ndarray
            One-element list: the posterior ``(num_states,)`` (or longer, truncated) over the factor.
        lr : float, optional
            Learning rate, must be positive; default 1.

        Raises
        ------
        SpecError
            If ``obs`` is not an integer index.
        ValueError
            If ``lr <= 0``.

        Notes
        -----
        Eq. (8) of the AIMAPP paper.
        """
        if not isinstance(obs, int | np.integer):
            raise SpecError("a sparse likelihood learns from an outcome index")
        q = np.asarray(qs[0], dtype=float)[: self.num_states]
        if lr <= 0:
            raise ValueError(f"learning rate must be positive, got {lr}")
        for s in np.flatnonzero(q > SUPPORT_CUTOFF):
            self._add(int(obs), int(s), lr * float(q[s]))

    # -- entries ----------------------------------------------------------------------------
    def learned(self, o: int, states: np.ndarray) -> np.ndarray:
        """Learned counts of outcome ``o`` at ``states`` (without the prior).

        Parameters
        ----------
        o : int
            Outcome index.
        states : numpy.ndarray
            ``(U,)`` int state indices.

        Returns
        -------
        numpy.ndarray
            ``(U,)`` float counts.
        """
        states = np.asarray(states, dtype=np.int64)
        return ((self.obs[states] == o) * self.cnt[states]).sum(axis=1)

    def counts_row(self, o: int) -> np.ndarray:
        """``pA[o, :]`` over the live states (prior share plus learned counts).

        Parameters
        ----------
        o : int
            Outcome index.

        Returns
        -------
        numpy.ndarray
            ``(num_states,)`` float counts.
        """
        n = self.num_states
        out = self.prior[:n] / self.num_obs
        idx = np.asarray(self.rows[o], dtype=np.int64)
        if idx.size:
            out[idx] += self.learned(o, idx)
        return out

    def row(self, o: int) -> np.ndarray:
        """``A[o, :]`` over the live states: the evidence of outcome ``o``.

        Parameters
        ----------
        o : int
            Outcome index.

        Returns
        -------
        numpy.ndarray
            ``(num_states,)`` float probabilities of ``o`` under each state.
        """
        return self.counts_row(o) / self.total()

    def expected_row(self, p: np.ndarray) -> np.ndarray:
        """``sum_o p[o] A[o, :]`` for a distribution ``p`` over the live outcomes.

        Parameters
        ----------
        p : numpy.ndarray
            ``(n,)`` float with ``n >= num_obs``; only its first ``num_obs`` entries are used.

        Returns
        -------
        numpy.ndarray
            ``(num_states,)`` float.
        """
        n = self.num_states
        p = np.asarray(p, dtype=float)[: self.num_obs]
        obs = self.obs[:n]
        learned = (np.where(obs >= 0, p[np.maximum(obs, 0)], 0.0) * self.cnt[:n]).sum(axis=1)
        return (p.sum() * self.prior[:n] / self.num_obs + learned) / self.total()

    def column(self, s: int) -> np.ndarray:
        """``A[:, s]`` over the live outcomes (dense, O(outcomes)).

        Parameters
        ----------
        s : int
            State index.

        Returns
        -------
        numpy.ndarray
            ``(num_obs,)`` float, sums to 1.
        """
        out = np.full(self.num_obs, self.prior[s] / self.num_obs)
        ok = self.obs[s] >= 0
        np.add.at(out, self.obs[s][ok], self.cnt[s][ok])
        return out / self.total([s])[0]

    def to_dense(self) -> np.ndarray:
        """Dense ``A`` (outcomes x states) of the live part, for tests, export and small models.

        Returns
        -------
        numpy.ndarray
            ``(num_obs, num_states)`` float, columns sum to 1.
        """
        return self.counts_dense() / np.maximum(self.total(), EPS)

    def counts_dense(self) -> np.ndarray:
        """Dense Dirichlet counts ``pA`` of the live part.

        Returns
        -------
        numpy.ndarray
            ``(num_obs, num_states)`` float.
        """
        n = self.num_states
        out = np.tile(self.prior[:n] / self.num_obs, (self.num_obs, 1))
        s_idx, k_idx = np.nonzero(self.obs[:n] >= 0)
        np.add.at(out, (self.obs[s_idx, k_idx], s_idx), self.cnt[s_idx, k_idx])
        return out

    def taught(self, threshold: float) -> np.ndarray:
        """Mask of live states whose largest count (prior share plus largest learned count) exceeds ``threshold``.

        Parameters
        ----------
        threshold : float
            Count threshold.

        Returns
        -------
        numpy.ndarray
            ``(num_states,)`` bool.
        """
        n = self.num_states
        top = np.max(self.cnt[:n], axis=1, initial=0.0)
        return self.prior[:n] / self.num_obs + top > threshold

    def outcomes_above(self, s: int, threshold: float) -> np.ndarray:
        """Outcomes ``o`` with ``A[o, s] >= threshold``.

        O(slots) unless the prior share alone reaches the threshold.

        Parameters
        ----------
        s : int
            State index.
        threshold : float
            Probability threshold.

        Returns
        -------
        numpy.ndarray
            Sorted int outcome indices.
        """
        T = self.total([s])[0]
        bg = self.prior[s] / self.num_obs
        if bg / T >= threshold:
            return np.flatnonzero(self.column(s) >= threshold)
        ok = (self.obs[s] >= 0) & ((bg + self.cnt[s]) / T >= threshold)
        return np.sort(self.obs[s][ok])

    def most_likely(self) -> np.ndarray:
        """Most likely learned outcome of each live state.

        Returns
        -------
        numpy.ndarray
            ``(num_states,)`` int outcome index, -1 where nothing was learned.
        """
        n = self.num_states
        k = np.argmax(self.cnt[:n], axis=1)
        best = self.obs[:n][np.arange(n), k]
        return np.where(self.cnt[:n][np.arange(n), k] > 0, best, -1)

    # -- planning statistics (O(slots) per state) ------------------------------------------
    def column_stats(self, states: np.ndarray, novelty: bool = True):
        """Column entropy and novelty weights of each state in ``states`` (O(slots) per state).

        Parameters
        ----------
        states : numpy.ndarray
            ``(U,)`` int state indices.
        novelty : bool, optional
            Whether to compute novelty weights (zeros otherwise); default True.

        Returns
        -------
        H : numpy.ndarray
            ``(U,)`` float, entropy (nats) of each column ``A[:, s]``.
        w_bg : numpy.ndarray
            ``(U,)`` float, novelty weight of each background (unlearned) outcome of the column.
        w_slots : numpy.ndarray
            ``(U, slots)`` float, novelty weight of each learned slot (0 for free slots).

        Notes
        -----
        The weights are :func:`cogmap.genmodel.dirichlet.novelty` of the counts, the parameter
        information gain term of Eq. (6) of the AIMAPP paper.
        """
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
        """Predicted outcome distributions of ``K`` beliefs over ``states``, compressed.

        ``num_obs - W`` outcomes that no state in ``states`` learned share the probability ``bg``.

        Parameters
        ----------
        states : numpy.ndarray
            ``(U,)`` int state indices.
        qs : numpy.ndarray
            ``(K, U)`` float beliefs over ``states``.

        Returns
        -------
        bg : numpy.ndarray
            ``(K,)`` float, probability of each unlearned outcome.
        outcomes : numpy.ndarray
            ``(W,)`` int, the sorted learned outcomes.
        values : numpy.ndarray
            ``(K, W)`` float, their probabilities.
        """
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
        """Spread per-slot values onto a dense (state, outcome) table.

        ``out[i, j]`` is ``per_slot[i, k]`` for the slot ``k`` of state ``states[i]`` holding outcome
        ``outcomes[j]``, and 0 where that state learned nothing of it.

        Parameters
        ----------
        states : numpy.ndarray
            ``(U,)`` int state indices.
        outcomes : numpy.ndarray
            ``(W,)`` int, sorted, containing every outcome learned at ``states``.
        per_slot : numpy.ndarray
            ``(U, slots)`` float values.

        Returns
        -------
        numpy.ndarray
            ``(U, W)`` float.
        """
        obs = self.obs[np.asarray(states, dtype=np.int64)]
        out = np.zeros((obs.shape[0], outcomes.size))
        rows, k = np.nonzero(obs >= 0)
        if rows.size:
            out[rows, np.searchsorted(outcomes, obs[rows, k])] = per_slot[rows, k]
        return out

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
    """Dense transitions ``prob[next, current, control]`` at capacity, with optional counts of the same shape.

    Parameters
    ----------
    prob : numpy.ndarray
        ``(capacity, capacity, num_controls)`` float ``B``; each live column ``prob[:n, s, u]`` sums to 1.
    counts : numpy.ndarray or None, optional
        Dirichlet counts ``pB`` of the same shape, or None (fixed transitions).
    """

    def __init__(self, prob: np.ndarray, counts: np.ndarray | None = None):
        self.prob = np.asarray(prob, dtype=float)
        self.counts = None if counts is None else np.asarray(counts, dtype=float)

    @property
    def capacity(self) -> int:
        """Number of states room is reserved for."""
        return self.prob.shape[0]

    @property
    def num_controls(self) -> int:
        """Number of controls (axis 2 of ``prob``)."""
        return self.prob.shape[2]

    def predict(self, q: np.ndarray, u: int) -> np.ndarray:
        """One step of a belief under control ``u``: ``B[:n, :n, u] @ q``.

        Parameters
        ----------
        q : numpy.ndarray
            ``(n,)`` float belief over the first ``n`` states.
        u : int
            Control index.

        Returns
        -------
        numpy.ndarray
            ``(n,)`` float predicted belief.
        """
        n = q.shape[0]
        return self.prob[:n, :n, u] @ q

    def column(self, s: int, u: int, n: int) -> np.ndarray:
        """A copy of ``B[:n, s, u]``, the distribution of the next state from ``s`` under ``u``.

        Parameters
        ----------
        s : int
            Current state.
        u : int
            Control index.
        n : int
            Number of live states.

        Returns
        -------
        numpy.ndarray
            ``(n,)`` float.
        """
        return self.prob[:n, s, u].copy()

    def to_dense(self, n: int | None = None) -> np.ndarray:
        """The live ``(n, n, num_controls)`` block (a view).

        Parameters
        ----------
        n : int, optional
            Number of live states; default the capacity.

        Returns
        -------
        numpy.ndarray
            ``(n, n, num_controls)`` float ``B[next, current, control]``.
        """
        n = self.capacity if n is None else n
        return self.prob[:n, :n]

    def control_dense(self, u: int, n: int) -> np.ndarray:
        """The live ``B[:, :, u]`` (next, current) block (a view).

        Parameters
        ----------
        u : int
            Control index.
        n : int
            Number of live states.

        Returns
        -------
        numpy.ndarray
            ``(n, n)`` float.
        """
        return self.prob[:n, :n, u]

    def counts_dense(self, n: int | None = None) -> np.ndarray | None:
        """The live block of the counts (a view), or None without counts.

        Parameters
        ----------
        n : int, optional
            Number of live states; default the capacity.

        Returns
        -------
        numpy.ndarray or None
            ``(n, n, num_controls)`` float.
        """
        n = self.capacity if n is None else n
        return None if self.counts is None else self.counts[:n, :n]

    def edges(self, threshold: float, n: int) -> tuple[np.ndarray, np.ndarray]:
        """Believed-possible moves: ``(src, dst)`` with ``B[dst, src, u] > threshold`` for some control.

        Self loops are excluded.

        Parameters
        ----------
        threshold : float
            Probability a move must exceed.
        n : int
            Number of live states.

        Returns
        -------
        src, dst : numpy.ndarray
            ``(E,)`` int source and destination states.
        """
        adj = (self.prob[:n, :n] > threshold).any(axis=2)
        np.fill_diagonal(adj, False)
        dst, src = np.nonzero(adj)
        return src, dst

    def control_edges(self, u: int, n: int, min_prob: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Moves under control ``u`` with probability at least ``min_prob`` (self loops excluded).

        Parameters
        ----------
        u : int
            Control index.
        n : int
            Number of live states.
        min_prob : float
            Smallest probability kept.

        Returns
        -------
        src, dst : numpy.ndarray
            ``(E,)`` int source and destination states.
        prob : numpy.ndarray
            ``(E,)`` float ``B[dst, src, u]``.
        """
        dst, src = np.nonzero(self.prob[:n, :n, u] >= min_prob)
        keep = src != dst
        return src[keep], dst[keep], self.prob[dst[keep], src[keep], u]

    def learn_soft(self, q_next: np.ndarray, q_prev: np.ndarray, u: int, lr: float, n: int,
                   floor: float = 1e-3) -> None:
        """Dirichlet update of one control under beliefs, ``counts[:, :, u] += lr * q_next (x) q_prev``.

        Touched counts are floored at ``floor``; then the columns ``q_prev`` reaches are renormalised.

        Parameters
        ----------
        q_next : numpy.ndarray
            ``(>= n,)`` float belief over the next state (first ``n`` entries used).
        q_prev : numpy.ndarray
            ``(>= n,)`` float belief over the previous state.
        u : int
            Control taken.
        lr : float
            Learning rate.
        n : int
            Number of live states.
        floor : float, optional
            Smallest count a touched entry keeps, default 1e-3.

        Raises
        ------
        ValueError
            If these transitions have no counts.

        Notes
        -----
        Eq. (8) of the AIMAPP paper, applied to ``B``.
        """
        if self.counts is None:
            raise ValueError("these transitions have no Dirichlet counts to learn")
        outer = lr * np.outer(q_next[:n], q_prev[:n])
        block = self.counts[:n, :n, u] + outer
        block = np.where(outer > 0, np.maximum(block, floor), block)
        self.counts[:n, :n, u] = block
        cols = np.flatnonzero(q_prev[:n] > 0)
        self.prob[:n, cols, u] = block[:, cols] / block[:, cols].sum(axis=0, keepdims=True)

    def add_state(self, s: int, prior_count: float) -> None:
        """Make state ``s`` stay put under every control (structural identity column).

        Parameters
        ----------
        s : int
            State index (within the capacity).
        prior_count : float
            Count given to staying, under every control, if there are counts.
        """
        self.prob[:, s, :] = 0.0
        self.prob[s, s, :] = 1.0
        if self.counts is not None:
            self.counts[:, s, :] = 0.0
            self.counts[s, s, :] = prior_count

    def grow(self, capacity: int) -> None:
        """Reallocate to a larger capacity, keeping every entry and count; new states stay put.

        Parameters
        ----------
        capacity : int
            New number of states, at least the current capacity.
        """
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
        """Hard update of one column: ``counts[target, s, u] += lr`` (floored at ``floor``).

        A negative ``lr`` removes belief in the move ``s -> target`` and adds ``-lr`` to staying at ``s``
        (and does nothing when that count is already 0). The column is then scaled down to at most
        ``max_concentration`` total counts and ``prob[:n, s, u]`` is set to the normalised counts.

        Parameters
        ----------
        s : int
            Current state.
        u : int
            Control.
        target : int
            Next state whose count changes.
        lr : float
            Signed learning rate (Table 7 of the AIMAPP paper lists the values for possible, impossible
            and predicted moves).
        n : int
            Number of live states.
        floor : float
            Smallest value the target count keeps.
        max_concentration : float
            Cap on the column's total count.
        """
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
    """Growable sparse ``B`` for one factor as padded successor lists, with optional Dirichlet counts.

    ``succ[s, u, k]`` is the k-th possible successor of state ``s`` under control ``u`` and
    ``prob[s, u, k]`` its probability; unused slots point at ``s`` with probability 0.

    Parameters
    ----------
    succ : numpy.ndarray
        ``(capacity, num_controls, slots)`` int successor states.
    prob : numpy.ndarray
        ``(capacity, num_controls, slots)`` float; ``prob[s, u].sum() == 1`` for each live ``s``.
    counts : numpy.ndarray or None, optional
        Dirichlet counts per slot, same shape as ``prob``, or None.
    """

    def __init__(self, succ: np.ndarray, prob: np.ndarray, counts: np.ndarray | None = None):
        self.succ = np.asarray(succ, dtype=np.int64)
        self.prob = np.asarray(prob, dtype=float)
        self.counts = None if counts is None else np.asarray(counts, dtype=float)

    # -- shape ---------------------------------------------------------------------------
    @property
    def capacity(self) -> int:
        """Number of states room is reserved for."""
        return self.succ.shape[0]

    @property
    def num_controls(self) -> int:
        """Number of controls."""
        return self.succ.shape[1]

    @property
    def slots(self) -> int:
        """Number of successor slots per (state, control)."""
        return self.succ.shape[2]

    @classmethod
    def empty(cls, capacity: int, num_controls: int, slots: int = 4, with_counts: bool = True):
        """Transitions in which every state self-loops under every control (an untried move leaves you in place).

        Parameters
        ----------
        capacity : int
            Number of states.
        num_controls : int
            Number of controls.
        slots : int, optional
            Successor slots per (state, control), default 4.
        with_counts : bool, optional
            Whether to hold counts (1 on staying), default True.

        Returns
        -------
        SparseTransitions
        """
        succ = np.broadcast_to(np.arange(capacity)[:, None, None], (capacity, num_controls, slots))
        prob = np.zeros((capacity, num_controls, slots))
        prob[:, :, 0] = 1.0
        counts = prob.copy() if with_counts else None
        return cls(succ.copy(), prob, counts)

    @classmethod
    def from_dense(cls, B: np.ndarray, slots: int | None = None, counts: np.ndarray | None = None):
        """Convert a dense ``(n, n, u)`` array (and counts of the same shape).

        Parameters
        ----------
        B : numpy.ndarray
            ``(n, n, num_controls)`` float ``B[next, current, control]``.
        slots : int, optional
            Slots per column; default the largest number of nonzero entries in a column.
        counts : numpy.ndarray, optional
            ``(n, n, num_controls)`` float counts; entries with a count but probability 0 get a slot too.

        Returns
        -------
        SparseTransitions
            With capacity ``n``.
        """
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
        """Dense copy of the first ``n`` states (tests, pymdp export).

        Parameters
        ----------
        n : int, optional
            Number of states; default the capacity.

        Returns
        -------
        numpy.ndarray
            ``(n, n, num_controls)`` float ``B[next, current, control]``.
        """
        n = self.capacity if n is None else n
        return np.stack([self.control_dense(a, n) for a in range(self.num_controls)], axis=2)

    def control_dense(self, u: int, n: int) -> np.ndarray:
        """Dense ``B[:, :, u]`` (next, current) of the first ``n`` states.

        Parameters
        ----------
        u : int
            Control index.
        n : int
            Number of states.

        Returns
        -------
        numpy.ndarray
            ``(n, n)`` float.
        """
        out = np.zeros((n, n))
        np.add.at(out, (self.succ[:n, u].ravel(), np.repeat(np.arange(n), self.slots)), self.prob[:n, u].ravel())
        return out

    def counts_dense(self, n: int | None = None) -> np.ndarray:
        """Dense counts of the first ``n`` states (zeros without counts).

        Parameters
        ----------
        n : int, optional
            Number of states; default the capacity.

        Returns
        -------
        numpy.ndarray
            ``(n, n, num_controls)`` float.
        """
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
        """Predictive distribution ``sum_s B[:, s, u] q[s]`` over the first ``len(q)`` states.

        Parameters
        ----------
        q : numpy.ndarray
            ``(n,)`` float belief.
        u : int
            Control index.

        Returns
        -------
        numpy.ndarray
            ``(n,)`` float predicted belief.
        """
        n = q.shape[0]
        w = (q[:, None] * self.prob[:n, u]).ravel()
        return np.bincount(self.succ[:n, u].ravel(), weights=w, minlength=n)[:n]

    def column(self, s: int, u: int, n: int) -> np.ndarray:
        """Dense ``B[:n, s, u]``, the distribution of the next state from ``s`` under ``u``.

        Parameters
        ----------
        s : int
            Current state.
        u : int
            Control index.
        n : int
            Number of live states.

        Returns
        -------
        numpy.ndarray
            ``(n,)`` float.
        """
        out = np.zeros(n)
        np.add.at(out, self.succ[s, u], self.prob[s, u])
        return out

    def edges(self, threshold: float, n: int) -> tuple[np.ndarray, np.ndarray]:
        """Believed-possible moves: ``(src, dst)`` pairs with probability above ``threshold`` (no self loops).

        Parameters
        ----------
        threshold : float
            Probability a move must exceed.
        n : int
            Number of live states.

        Returns
        -------
        src, dst : numpy.ndarray
            ``(E,)`` int source and destination states (one pair per slot and control).
        """
        s = self.succ[:n]
        ok = (self.prob[:n] > threshold) & (s != np.arange(n)[:, None, None])
        src = np.broadcast_to(np.arange(n)[:, None, None], s.shape)[ok]
        return src, s[ok]

    def control_edges(self, u: int, n: int, min_prob: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Moves under control ``u`` with probability at least ``min_prob`` (self loops excluded).

        Parameters
        ----------
        u : int
            Control index.
        n : int
            Number of live states.
        min_prob : float
            Smallest probability kept.

        Returns
        -------
        src, dst : numpy.ndarray
            ``(E,)`` int source and destination states.
        prob : numpy.ndarray
            ``(E,)`` float probabilities.
        """
        src = np.repeat(np.arange(n), self.slots)
        dst, prob = self.succ[:n, u].ravel(), self.prob[:n, u].ravel()
        keep = (prob >= min_prob) & (src != dst)
        return src[keep], dst[keep], prob[keep]

    def add_state(self, s: int, prior_count: float) -> None:
        """Make state ``s`` stay put under every control.

        Parameters
        ----------
        s : int
            State index (within the capacity).
        prior_count : float
            Count given to staying, under every control, if there are counts.
        """
        self.succ[s] = s
        self.prob[s] = 0.0
        self.prob[s, :, 0] = 1.0
        if self.counts is not None:
            self.counts[s] = 0.0
            self.counts[s, :, 0] = prior_count

    def learn(self, s: int, u: int, target: int, lr: float, n: int, floor: float, max_concentration: float) -> None:
        """As :meth:`DenseTransitions.learn`, on the slot of ``target`` (claimed if new).

        Parameters
        ----------
        s : int
            Current state.
        u : int
            Control.
        target : int
            Next state whose count changes.
        lr : float
            Signed learning rate; negative moves the mass to staying.
        n : int
            Number of live states (unused by the sparse layout).
        floor : float
            Smallest value the target count keeps.
        max_concentration : float
            Cap on the column's total count.
        """
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
        """Reallocate to a larger capacity, keeping every entry and count; new states stay put.

        Parameters
        ----------
        capacity : int
            New number of states, at least the current capacity.
        """
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
        """Slot holding ``target`` in column ``(s, u)``; claims a free slot when ``create``.

        A slot is in use when its probability or count is positive. Widens the arrays (doubling the
        slots) when no slot is free.

        Parameters
        ----------
        s : int
            Current state.
        u : int
            Control.
        target : int
            Successor state.
        create : bool, optional
            Whether to claim a slot when ``target`` has none, default True.

        Returns
        -------
        int
            Slot index, or -1 when ``target`` has no slot and ``create`` is False.
        """
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
        """Set ``prob[s, u]`` to the normalised counts of that column (left alone if the counts sum to 0).

        Parameters
        ----------
        s : int
            State.
        u : int
            Control.
        """
        c = self.counts[s, u]
        total = c.sum()
        if total > 0:
            self.prob[s, u] = c / total


class DependentTransitions:
    """Dense transitions of a factor whose next state depends on the previous states of several factors.

    ``prob[next, s_d1, ..., s_dk, control]`` (pymdp 1.0's ``B_dependencies`` layout): the next state
    of the factor given the previous states of the factors ``deps`` (in that order; the factor itself
    is among them) and its control. Such a factor is neither growable nor padded to a capacity, so
    the live block is the whole array. The single-factor operations (``predict``, ``column``,
    ``control_dense``, ``edges``, learning, growth) do not apply and refuse with an error naming the
    dependencies; predictions contract ``prob`` with the beliefs of every dependency
    (:meth:`predict_from`).

    Parameters
    ----------
    prob : numpy.ndarray
        ``(n_f, *n_deps, num_controls)`` float; every column ``prob[:, s_d1, ..., s_dk, u]`` sums to 1.
    deps : tuple of int
        Indices of the factors the next state depends on (the axes 1..k of ``prob``).
    counts : numpy.ndarray or None, optional
        Dirichlet counts ``pB`` of the same shape, or None.
    name : str, optional
        Name of the factor, for messages.
    """

    def __init__(self, prob: np.ndarray, deps: tuple[int, ...], counts: np.ndarray | None = None, name: str = ""):
        self.prob = np.asarray(prob, dtype=float)
        self.deps = tuple(int(d) for d in deps)
        self.counts = None if counts is None else np.asarray(counts, dtype=float)
        self.name = name
        if self.prob.ndim != len(self.deps) + 2:
            raise ValueError(f"transitions of factor '{name}': {self.prob.ndim} axes for {len(self.deps)} "
                             "dependencies (expected next, one axis per dependency, control)")

    @property
    def capacity(self) -> int:
        """Number of states of the factor (no room is reserved)."""
        return self.prob.shape[0]

    @property
    def num_controls(self) -> int:
        """Number of controls (the last axis of ``prob``)."""
        return self.prob.shape[-1]

    def predict_from(self, qs_deps, u: int) -> np.ndarray:
        """Mean-field prediction ``sum_{s_deps} B[:, s_deps, u] prod_d q_d(s_d)``.

        Parameters
        ----------
        qs_deps : sequence of numpy.ndarray
            ``(n_d,)`` float belief of each dependency, in the order of ``deps``.
        u : int
            Control index.

        Returns
        -------
        numpy.ndarray
            ``(n_f,)`` float predicted belief.
        """
        x = self.prob[..., u]
        for q in reversed(qs_deps):  # contract the last dependency axis first
            x = x @ q
        return x

    def _refuse(self, what: str):
        from .spec import SpecError

        names = self.name or "this factor"
        raise SpecError(f"factor '{names}': its transitions depend on the factors {list(self.deps)} "
                        f"(B_dependencies); {what} needs transitions that depend on the factor alone")

    def predict(self, q: np.ndarray, u: int) -> np.ndarray:
        """Refused: the prediction needs every dependency's belief (:meth:`predict_from`,
        :func:`cogmap.inference.base.predict_factorised`)."""
        self._refuse("a one-factor prediction (use cogmap.inference.base.predict_factorised)")

    def column(self, s: int, u: int, n: int) -> np.ndarray:
        """Refused (a column needs the states of every dependency)."""
        self._refuse("a single-state transition column")

    def control_dense(self, u: int, n: int) -> np.ndarray:
        """Refused (there is no ``(next, current)`` matrix)."""
        self._refuse("a (next, current) transition matrix")

    def to_dense(self, n: int | None = None) -> np.ndarray:
        """The whole ``(n_f, *n_deps, num_controls)`` array (a view; nothing is padded)."""
        return self.prob

    def counts_dense(self, n: int | None = None) -> np.ndarray | None:
        """The counts (a view), or None without counts."""
        return self.counts

    def edges(self, threshold: float, n: int):
        """Refused (moves between states of one factor are not defined)."""
        self._refuse("the graph of believed-possible moves")

    def control_edges(self, u: int, n: int, min_prob: float):
        """Refused (moves between states of one factor are not defined)."""
        self._refuse("the graph of believed-possible moves")

    def learn_soft(self, *args, **kwargs) -> None:
        """Refused (learning these counts is not supported yet)."""
        self._refuse("learning B")

    def learn(self, *args, **kwargs) -> None:
        """Refused (learning these counts is not supported yet)."""
        self._refuse("learning B")

    def add_state(self, s: int, prior_count: float) -> None:
        """Refused (the factor is not growable)."""
        self._refuse("growth")

    def grow(self, capacity: int) -> None:
        """Refused (the factor is not growable)."""
        self._refuse("growth")

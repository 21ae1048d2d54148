"""The arrays planning needs, as plain data, and the per-decision derived quantities.

:class:`PlanningArrays` holds a model's arrays (pymdp layout, no batch axis) and the planning
inputs that are not part of the model (target pose, goal states). It may hold arrays at a
capacity larger than the live sizes: planning only reads live entries. :func:`from_model` is
the thin adapter from a compiled :class:`cogmap.genmodel.Model` (no copies).

:func:`prepare` computes what one decision reuses: column entropies and novelty weights
(dense factors, or lazily per touched state for sparse transitions, so the cost does not
grow with the size of the map) and goal distances for the inductive term.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from cogmap.genmodel.likelihood import DenseLikelihood, SparseLikelihood
from cogmap.genmodel.transitions import DenseTransitions, DependentTransitions, SparseTransitions

from . import inductive as ind
from .efe import EPS, entropy, novelty_weights


@dataclass(frozen=True)
class PlanningArrays:
    """A model's arrays (pymdp layout, no batch axis) and the planning inputs that are not part of the model.

    Arrays may be at a capacity larger than the live sizes: planning only reads live entries. Raw
    ``A``/``B`` arrays are wrapped on construction into :class:`DenseLikelihood` /
    :class:`DenseTransitions` with ``pA``/``pB`` as their counts (``pA``/``pB`` are then None).

    Attributes
    ----------
    A : list
        Per modality, a likelihood object or ``(obs_cap, *state_caps[deps])`` float array.
    A_deps : tuple of tuple of int
        Factors each modality depends on.
    B : list
        Per factor, a transition object or ``(cap, cap, num_controls)`` float array.
    C : list of numpy.ndarray
        Per modality, ``(obs_cap,)`` float log-preferences.
    num_states, num_obs, num_controls : tuple of int
        Live states per factor, live outcomes per modality, controls per factor.
    C_states : list of numpy.ndarray or None
        Per factor, ``(state_cap,)`` float log-preferences over states.
    pA, pB : list or None
        Counts for raw ``A`` / dense ``B`` arrays only.
    stay : tuple or None
        Stay control of each factor (or None).
    poses : numpy.ndarray or None
        ``(state_cap, 2)`` float stored poses of ``pose_factor``, metres, world frame.
    pose_factor : int
        Factor carrying poses, default 0.
    pose_sigma : float
        Width (metres) of the position preference, default 1.
    target_pose : numpy.ndarray or None
        ``(2,)`` float target position (metres) for :func:`position_preference`.
    goal_states : numpy.ndarray or None
        Int preferred states of ``goal_factor`` for the inductive term.
    goal_factor : int
        Factor of the goal states, default 0.
    inductive_threshold : float
        Transition probability above which a move counts as possible (inductive term), default 0.5.
    inductive_depth : int
        Horizon of the inductive term, default 10.
    collision_pref : float
        Log-preference of a collision (no collision: 0), default -10.
    control_factor : int
        Factor whose controls the obstacle signal refers to, default 0.
    view : numpy.ndarray or None
        Per state of ``pose_factor``, the unseen fraction of its view, in [0, 1].
    B_deps : tuple of tuple of int or None
        Per factor, the factors whose previous states its next state depends on (pymdp's
        ``B_dependencies``; ``B[f]`` then has shape ``(n_f, *n_deps, num_controls)``); default
        ``(f,)`` for every factor.
    """
    A: list  # A[m]: (obs_cap, *state_caps[deps]); live part [:num_obs[m], :num_states...]
    A_deps: tuple
    B: list  # DenseTransitions / SparseTransitions (raw (cap, cap, u) arrays are wrapped, with pB)
    C: list
    num_states: tuple
    num_obs: tuple
    num_controls: tuple
    C_states: list | None = None
    pA: list | None = None  # counts for raw A arrays only (likelihood objects hold their own)
    pB: list | None = None  # counts for raw dense B arrays only (transition objects hold their own)
    stay: tuple | None = None
    poses: np.ndarray | None = None
    pose_factor: int = 0
    pose_sigma: float = 1.0
    target_pose: np.ndarray | None = None
    goal_states: np.ndarray | None = None  # preferred states of ``goal_factor`` (inductive)
    goal_factor: int = 0
    inductive_threshold: float = 0.5
    inductive_depth: int = 10
    collision_pref: float = -10.0  # log-preference of a collision (no collision: 0)
    control_factor: int = 0  # factor whose controls the obstacle signal refers to
    view: np.ndarray | None = None  # per state of pose_factor: unseen fraction of its view, in [0, 1]
    B_deps: tuple | None = None  # per factor: factors its next state depends on (default: itself)

    def __post_init__(self):
        deps = tuple((f,) for f in range(len(self.B))) if self.B_deps is None else \
            tuple(tuple(int(d) for d in fd) for fd in self.B_deps)
        object.__setattr__(self, "B_deps", deps)
        likelihoods = [
            DenseLikelihood(A, None if self.pA is None else self.pA[m], self.num_obs[m],
                            tuple(self.num_states[f] for f in self.A_deps[m]))
            if isinstance(A, np.ndarray) else A
            for m, A in enumerate(self.A)
        ]
        object.__setattr__(self, "A", likelihoods)
        object.__setattr__(self, "pA", None)
        wrapped = [
            (DenseTransitions(B, None if self.pB is None else self.pB[f]) if deps[f] == (f,) else
             DependentTransitions(B, deps[f], None if self.pB is None else self.pB[f], f"factor_{f}"))
            if isinstance(B, np.ndarray) else B
            for f, B in enumerate(self.B)
        ]
        object.__setattr__(self, "B", wrapped)
        object.__setattr__(self, "pB", None)

    @property
    def num_factors(self) -> int:
        """Number of factors."""
        return len(self.B)

    @property
    def has_B_deps(self) -> bool:
        """Whether some factor's next state depends on other factors' previous states."""
        return any(d != (f,) for f, d in enumerate(self.B_deps))

    def is_sparse(self, f: int) -> bool:
        """Whether factor ``f`` has sparse transitions.

        Parameters
        ----------
        f : int
            Factor index.

        Returns
        -------
        bool
        """
        return isinstance(self.B[f], SparseTransitions)

    def live_A(self, m: int) -> np.ndarray:
        """Dense live ``A[m]`` (a sparse likelihood is densified: small models only).

        Parameters
        ----------
        m : int
            Modality index.

        Returns
        -------
        numpy.ndarray
            ``(num_obs[m], *live states of its dependencies)`` float.
        """
        return self.A[m].to_dense()

    def live_B(self, f: int) -> np.ndarray:
        """Dense live ``B[f]``.

        Parameters
        ----------
        f : int
            Factor index.

        Returns
        -------
        numpy.ndarray
            ``(n, n, num_controls[f])`` float with ``n = num_states[f]``.
        """
        return self.B[f].to_dense(self.num_states[f])

    def live_pA(self, m: int):
        """Live Dirichlet counts of ``A[m]`` (None without counts).

        Parameters
        ----------
        m : int
            Modality index.

        Returns
        -------
        numpy.ndarray or None
            Shaped as :meth:`live_A`.
        """
        return self.A[m].counts_dense()

    def live_pB(self, f: int):
        """Live Dirichlet counts of ``B[f]`` (None without counts).

        Parameters
        ----------
        f : int
            Factor index.

        Returns
        -------
        numpy.ndarray or None
            ``(n, n, num_controls[f])`` float.
        """
        B = self.B[f]
        return None if B.counts is None else B.counts_dense(self.num_states[f])


def from_model(
    model,
    *,
    target_pose=None,
    goal_states=None,
    goal_factor: int | None = None,
    collision_pref: float | None = None,
    view=None,
) -> PlanningArrays:
    """Adapter: the arrays of a compiled :class:`cogmap.genmodel.Model` (views, nothing copied).

    Goal states for the inductive term default to the states of maximal positive ``C_states``
    (none when ``C_states`` is flat) and, with a target pose, the stored pose nearest to it
    (within the influence radius).

    Parameters
    ----------
    model : Model
        Compiled model.
    target_pose : array_like, optional
        ``(2,)`` float target position, metres.
    goal_states : array_like, optional
        Int preferred states (overrides the defaults above).
    goal_factor : int, optional
        Factor of the goal states; default the pose factor (or 0).
    collision_pref : float, optional
        Log-preference of a collision; default the model's ``collision_preference``, else -10.
    view : array_like, optional
        Per state, the unseen fraction of its view, in [0, 1].

    Returns
    -------
    PlanningArrays
    """
    pose = model.pose
    pf = pose.factor if pose is not None else 0
    gf = pf if goal_factor is None else goal_factor
    ind_spec = model.inductive
    if goal_states is None:
        n = model.num_states[gf]
        cs = model.C_states[gf][:n]
        goals = []
        if n and cs.max() > 0 and cs.max() > cs.min():
            goals.extend(np.flatnonzero(cs >= cs.max() - 1e-12).tolist())
        if target_pose is not None and pose is not None and pose.factor == gf:
            d = np.linalg.norm(pose.poses[:n] - np.asarray(target_pose, dtype=float), axis=1)
            if d.size and d.min() <= pose.influence_radius:
                goals.append(int(d.argmin()))
        goal_states = np.unique(np.asarray(goals, dtype=np.int64))
    cp = collision_pref if collision_pref is not None else model.collision_preference
    return PlanningArrays(
        A=list(model.A),
        A_deps=tuple(tuple(d) for d in model.A_deps),
        B=list(model.B),
        C=list(model.C),
        num_states=tuple(model.num_states),
        num_obs=tuple(model.num_obs),
        num_controls=tuple(model.num_controls),
        C_states=list(model.C_states),
        stay=tuple(f.stay for f in model.factors),
        poses=None if pose is None else pose.poses,
        pose_factor=pf,
        pose_sigma=1.0 if pose is None else float(pose.sigma),
        target_pose=None if target_pose is None else np.asarray(target_pose, dtype=float),
        goal_states=np.asarray(goal_states, dtype=np.int64),
        goal_factor=gf,
        inductive_threshold=0.5 if ind_spec is None else float(ind_spec.threshold),
        inductive_depth=10 if ind_spec is None else int(ind_spec.depth),
        collision_pref=-10.0 if cp is None else float(cp),
        control_factor=pf,
        view=None if view is None else np.asarray(view, dtype=float),
        B_deps=getattr(model, "B_deps", None),
    )


def as_arrays(model) -> PlanningArrays:
    """:class:`PlanningArrays` as they are, or a compiled ``Model`` through :func:`from_model`."""
    if isinstance(model, PlanningArrays):
        return model
    if hasattr(model, "factors") and hasattr(model, "A_deps"):
        return from_model(model)
    raise TypeError(f"planning needs a compiled Model or PlanningArrays, got {type(model).__name__}")


@dataclass
class Prepared:
    """Derived quantities for one decision (dense: full arrays; local: per-state caches).

    Built by :func:`prepare`.

    Attributes
    ----------
    arrays : PlanningArrays
        The planning inputs.
    local : bool
        Whether this is the local path (one sparse factor, per-state caches).
    B : list of numpy.ndarray
        Dense path: live ``(n, n, u)`` transition arrays per factor (``(n_f, *n_deps, u)`` for a
        factor that depends on several, ``arrays.B_deps``).
    HA : list of numpy.ndarray
        Dense path: column entropies (nats) of each live ``A[m]``.
    wA : list
        Dense path: novelty weights of each ``pA[m]`` (or None).
    wB : list
        Dense path: novelty weights of each ``pB[f]`` (or None).
    dist : numpy.ndarray or None
        Goal distances (in believed-possible moves) of the states of ``goal_factor``; None without
        a goal.
    need_novelty : bool
        Whether novelty weights are computed.
    """

    arrays: PlanningArrays
    local: bool = False  # single sparse factor, per-state caches
    B: list = field(default_factory=list)  # dense path: live (n, n, u) transition arrays
    HA: list = field(default_factory=list)  # dense: column entropies per modality
    wA: list = field(default_factory=list)  # dense: novelty weights per modality (or None)
    wB: list = field(default_factory=list)  # dense: novelty weights per factor (or None)
    dist: np.ndarray | None = None  # goal distances of goal_factor (None: no goal)
    need_novelty: bool = True
    _cache: dict = field(default_factory=dict)  # local path, dense likelihoods: modality -> _Columns

    def column_stats(self, m: int, U: np.ndarray):
        """``(H, w_bg, w_slots)`` of likelihood ``m`` at states ``U`` (see ``SparseLikelihood.column_stats``).

        A sparse likelihood computes them in O(slots) per state; a dense one in O(outcomes), so they are
        kept for the rest of the decision.

        Parameters
        ----------
        m : int
            Modality index.
        U : numpy.ndarray
            ``(U,)`` int state indices.

        Returns
        -------
        H : numpy.ndarray
            ``(U,)`` float column entropies.
        w_bg : numpy.ndarray
            ``(U,)`` float background novelty weights.
        w_slots : numpy.ndarray
            ``(U, slots)`` float novelty weight of each slot (each outcome for a dense likelihood).
        """
        A = self.arrays.A[m]
        novelty = self.need_novelty and A.has_counts
        if isinstance(A, SparseLikelihood):
            return A.column_stats(U, novelty)
        cache = self._cache.get(m)
        if cache is None:
            cache = self._cache[m] = _Columns(np.full(max(A.num_states[0], 1), -1, dtype=np.int64))
        return cache.get(A, np.asarray(U, dtype=np.int64), novelty)


@dataclass
class _Columns:
    """Column statistics of a dense likelihood, computed once per state and decision."""

    slot: np.ndarray  # state -> row of the arrays below (-1: not computed)
    H: np.ndarray = field(default_factory=lambda: np.zeros(0))
    w_bg: np.ndarray = field(default_factory=lambda: np.zeros(0))
    w_slots: np.ndarray | None = None
    used: int = 0

    def get(self, A, U: np.ndarray, novelty: bool):
        new = np.unique(U[self.slot[U] < 0])
        if new.size:
            H, w_bg, w_slots = A.column_stats(new, novelty)
            rows = np.arange(self.used, self.used + new.size)
            if self.used + new.size > self.H.size:  # double the room
                cap = max(64, 2 * (self.used + new.size))
                self.H = np.resize(self.H, cap)
                self.w_bg = np.resize(self.w_bg, cap)
                grown = np.zeros((cap, w_slots.shape[1]))
                if self.w_slots is not None:
                    grown[: self.used] = self.w_slots[: self.used]
                self.w_slots = grown
            self.H[rows], self.w_bg[rows], self.w_slots[rows] = H, w_bg, w_slots
            self.slot[new] = rows
            self.used += new.size
        idx = self.slot[U]
        return self.H[idx], self.w_bg[idx], self.w_slots[idx]

def prepare(
    arrays: PlanningArrays,
    local: bool | None = None,
    need_novelty: bool = True,
    need_goal: bool = True,
) -> Prepared:
    """Per-decision derived arrays: column entropies, novelty weights and goal distances.

    Parameters
    ----------
    arrays : PlanningArrays
        The planning inputs.
    local : bool, optional
        Use the local path's per-state caches; default: when there is one sparse factor. Otherwise
        everything is dense (sparse transitions are densified: small models only).
    need_novelty : bool, optional
        Whether to compute the novelty weights, default True.
    need_goal : bool, optional
        Whether to compute goal distances for the inductive term, default True.

    Returns
    -------
    Prepared

    Raises
    ------
    ValueError
        If ``local`` is True but the arrays are not a single factor with sparse transitions.
    """
    a = arrays
    if local is None:
        local = a.num_factors == 1 and a.is_sparse(0)
    if local and not (a.num_factors == 1 and a.is_sparse(0)):
        raise ValueError("the local planning path needs a single factor with sparse transitions")
    if a.has_B_deps and any(a.is_sparse(f) for f in range(a.num_factors)):
        raise ValueError("planning with transitions that depend on several factors (B_dependencies) is supported "
                         "on dense models only; this one has sparse transitions")
    prep = Prepared(arrays=a, local=local, need_novelty=need_novelty)
    if not local:
        prep.B = [a.live_B(f) for f in range(a.num_factors)]
        for m in range(len(a.A)):
            A_m = a.live_A(m)
            prep.HA.append(entropy(A_m, axis=0))
            pA_m = a.live_pA(m) if need_novelty else None
            prep.wA.append(None if pA_m is None else novelty_weights(pA_m))
        for f in range(a.num_factors):
            pB_f = a.live_pB(f) if need_novelty else None
            prep.wB.append(None if pB_f is None else novelty_weights(pB_f))
    if need_goal and a.goal_states is not None and len(a.goal_states):
        f = a.goal_factor
        n = a.num_states[f]
        src, dst = a.B[f].edges(a.inductive_threshold, n)
        prep.dist = ind.goal_distances(src, dst, a.goal_states, n, a.inductive_depth)
    return prep


__all__ = ["EPS", "PlanningArrays", "Prepared", "as_arrays", "from_model", "prepare"]

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

from . import inductive as ind
from .efe import EPS, entropy, novelty_weights


@dataclass(frozen=True)
class PlanningArrays:
    A: list  # A[m]: (obs_cap, *state_caps[deps]); live part [:num_obs[m], :num_states...]
    A_deps: tuple
    B: list  # dense (cap, cap, u) or an object with succ/prob/counts (sparse, one factor)
    C: list
    num_states: tuple
    num_obs: tuple
    num_controls: tuple
    C_states: list | None = None
    pA: list | None = None
    pB: list | None = None  # dense counts; sparse factors keep counts on B[f].counts
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

    @property
    def num_factors(self) -> int:
        return len(self.B)

    def is_sparse(self, f: int) -> bool:
        return hasattr(self.B[f], "succ")

    def live_A(self, m: int) -> np.ndarray:
        if not isinstance(self.A[m], np.ndarray):  # sparse likelihood: densified (small models only)
            return self.A[m].to_dense()
        idx = (slice(0, self.num_obs[m]),) + tuple(slice(0, self.num_states[f]) for f in self.A_deps[m])
        return self.A[m][idx]

    def live_B(self, f: int) -> np.ndarray:
        n = self.num_states[f]
        if self.is_sparse(f):
            return self.B[f].to_dense(n)
        return self.B[f][:n, :n]

    def live_pA(self, m: int):
        if not isinstance(self.A[m], np.ndarray):
            return self.A[m].counts_dense()
        if self.pA is None or self.pA[m] is None:
            return None
        idx = (slice(0, self.num_obs[m]),) + tuple(slice(0, self.num_states[f]) for f in self.A_deps[m])
        return self.pA[m][idx]

    def live_pB(self, f: int):
        n = self.num_states[f]
        if self.is_sparse(f):
            c = self.B[f].counts
            return None if c is None else self.B[f].counts_dense(n)
        if self.pB is None or self.pB[f] is None:
            return None
        return self.pB[f][:n, :n]


def from_model(
    model,
    *,
    target_pose=None,
    goal_states=None,
    goal_factor: int | None = None,
    collision_pref: float | None = None,
    view=None,
) -> PlanningArrays:
    """Adapter: the arrays of a compiled ``cogmap.genmodel.Model`` (views, nothing copied).

    Goal states for the inductive term default to the states of maximal positive ``C_states``
    (none when ``C_states`` is flat) and, with a target pose, the stored pose nearest to it
    (within the influence radius).
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
        pA=list(model.pA),
        pB=list(model.pB),
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
    """Derived quantities for one decision (dense: full arrays; sparse: per-state caches)."""

    arrays: PlanningArrays
    local: bool = False  # single sparse factor, per-state caches
    B: list = field(default_factory=list)  # dense path: live (n, n, u) transition arrays
    HA: list = field(default_factory=list)  # dense: column entropies per modality
    wA: list = field(default_factory=list)  # dense: novelty weights per modality (or None)
    wB: list = field(default_factory=list)  # dense: novelty weights per factor (or None)
    dist: np.ndarray | None = None  # goal distances of goal_factor (None: no goal)
    _slot: np.ndarray | None = None  # sparse caches: state -> column slot (-1: not computed)
    _HA_cols: list = field(default_factory=list)
    _wA_cols: list = field(default_factory=list)
    _used: int = 0
    need_novelty: bool = True

    # lazily filled column statistics for the sparse (single-factor) path
    def columns(self, U: np.ndarray) -> tuple[list, list]:
        """Entropies ``H[A_m[:, s]]`` and novelty columns ``wA_m[:, s]`` for states ``U``."""
        slots = self._slot[U]
        new = U[slots < 0]
        if new.size:
            self._ensure_room(new.size)
            a = self.arrays
            k = np.arange(self._used, self._used + new.size)
            for m in range(len(a.A)):
                if not isinstance(a.A[m], np.ndarray):
                    continue  # a sparse likelihood computes its own column statistics
                cols = a.A[m][: a.num_obs[m], new]
                self._HA_cols[m][k] = entropy(cols, axis=0)
                if self._wA_cols[m] is not None:
                    self._wA_cols[m][:, k] = novelty_weights(a.pA[m][: a.num_obs[m], new])
            self._slot[new] = k
            self._used += new.size
            slots = self._slot[U]
        HA = [h[slots] for h in self._HA_cols]
        wA = [None if w is None else w[:, slots] for w in self._wA_cols]
        return HA, wA

    def _ensure_room(self, extra: int) -> None:
        cap = self._HA_cols[0].shape[0]
        if self._used + extra <= cap:
            return
        new_cap = max(2 * cap, self._used + extra)
        self._HA_cols = [np.concatenate([h, np.zeros(new_cap - cap)]) for h in self._HA_cols]
        self._wA_cols = [
            None if w is None else np.concatenate([w, np.zeros((w.shape[0], new_cap - cap))], axis=1)
            for w in self._wA_cols
        ]


def prepare(
    arrays: PlanningArrays,
    local: bool | None = None,
    need_novelty: bool = True,
    need_goal: bool = True,
) -> Prepared:
    """Per-decision derived arrays (see module docstring). ``local`` (default: one sparse
    factor) selects the per-state caches of the local path; otherwise everything is dense
    (sparse transitions are densified: small models only)."""
    a = arrays
    if local is None:
        local = a.num_factors == 1 and a.is_sparse(0)
    if local and not (a.num_factors == 1 and a.is_sparse(0)):
        raise ValueError("the local planning path needs a single factor with sparse transitions")
    prep = Prepared(arrays=a, local=local, need_novelty=need_novelty)
    if local:
        n = a.num_states[0]
        prep._slot = np.full(max(n, 1), -1, dtype=np.int64)
        cap = 64
        prep._HA_cols = [np.zeros(cap) for _ in a.A]
        prep._wA_cols = [
            None
            if (not need_novelty or a.pA is None or a.pA[m] is None or not isinstance(a.A[m], np.ndarray))
            else np.zeros((a.num_obs[m], cap))
            for m in range(len(a.A))
        ]
    else:
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
        if a.is_sparse(f):
            src, dst = ind.edges_sparse(a.B[f].succ, a.B[f].prob, a.inductive_threshold, n)
        else:
            src, dst = ind.edges_dense(a.B[f], a.inductive_threshold, n)
        prep.dist = ind.goal_distances(src, dst, a.goal_states, n, a.inductive_depth)
    return prep


__all__ = ["EPS", "PlanningArrays", "Prepared", "as_arrays", "from_model", "prepare"]

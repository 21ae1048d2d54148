"""The compiled generative model: arrays at a reserved capacity plus masks of live entries.

Growth (:meth:`Model.add_state`, :meth:`Model.add_observation`) writes into reserved space;
arrays are reallocated only when a capacity doubles, so compiled (jitted) functions keyed on
shapes are reused and the number of reallocations after ``n`` growth steps is about
``log2(n)`` (counted in :attr:`Model.compile_count`).

Each likelihood and transition factor is one object that owns its Dirichlet counts and offers
the same operations whether dense or sparse (``likelihood.py``, ``transitions.py``); the model
holds them, the live sizes and the poses. The maths lives in pure functions
(``cogmap.inference``, ``cogmap.planning``) that take these objects.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .capacity import pad_axis
from .likelihood import SparseLikelihood
from .spatial import PoseIndex
from .spec import Factor, InductiveSpec, Modality, SpecError
from .transitions import SparseTransitions


@dataclass
class PoseModel:
    """Stored metric pose per state (B_p) and the action-conditioned pose prediction."""

    factor: int
    poses: np.ndarray  # (capacity, 2)
    headings: np.ndarray  # (num_moves,)
    step: float
    influence_radius: float
    sigma: float
    index: PoseIndex | None = field(default=None, repr=False)  # built on first use (Model.pose_index)

    def predict(self, pose: np.ndarray, control: int, stay: int | None) -> np.ndarray:
        """Pose after ``control`` from ``pose`` (the stay control keeps the pose)."""
        if stay is not None and control == stay:
            return np.asarray(pose, dtype=float).copy()
        h = self.headings[control if stay is None or control < stay else control - 1]
        return np.asarray(pose, dtype=float) + self.step * np.array([np.cos(h), np.sin(h)])


@dataclass
class Model:
    """Arrays of a compiled model (pymdp layout, no batch axis) at capacity, with live sizes."""

    factors: tuple[Factor, ...]
    modalities: tuple[Modality, ...]
    A: list  # DenseLikelihood or SparseLikelihood (each holds its own counts)
    A_deps: tuple[tuple[int, ...], ...]
    B: list  # DenseTransitions or SparseTransitions (each holds its own counts)
    C: list[np.ndarray]
    D: list[np.ndarray]
    C_states: list[np.ndarray]
    num_states: list[int]
    num_obs: list[int]
    pose: PoseModel | None = None
    inductive: InductiveSpec | None = None
    collision_preference: float | None = None
    prior_count: float = 1.0
    compile_count: int = 0

    # -- names and shapes ------------------------------------------------------------------
    @property
    def factor_names(self) -> tuple[str, ...]:
        return tuple(f.name for f in self.factors)

    @property
    def modality_names(self) -> tuple[str, ...]:
        return tuple(m.name for m in self.modalities)

    @property
    def num_controls(self) -> list[int]:
        return [f.num_controls for f in self.factors]

    def factor_index(self, name: str | int) -> int:
        if isinstance(name, int | np.integer):
            if not 0 <= int(name) < len(self.factors):
                raise SpecError(f"factor index {name} out of range (have {len(self.factors)})")
            return int(name)
        try:
            return self.factor_names.index(name)
        except ValueError:
            raise SpecError(f"unknown factor '{name}' (known: {list(self.factor_names)})") from None

    def modality_index(self, name: str | int) -> int:
        if isinstance(name, int | np.integer):
            if not 0 <= int(name) < len(self.modalities):
                raise SpecError(f"modality index {name} out of range")
            return int(name)
        try:
            return self.modality_names.index(name)
        except ValueError:
            known = list(self.modality_names)
            raise SpecError(f"unknown modality '{name}' (known: {known})") from None

    def state_capacity(self, f: int) -> int:
        return self.D[f].shape[0]

    def obs_capacity(self, m: int) -> int:
        return self.C[m].shape[0]

    def state_mask(self, f: int) -> np.ndarray:
        mask = np.zeros(self.state_capacity(f), dtype=bool)
        mask[: self.num_states[f]] = True
        return mask

    def obs_mask(self, m: int) -> np.ndarray:
        mask = np.zeros(self.obs_capacity(m), dtype=bool)
        mask[: self.num_obs[m]] = True
        return mask

    def is_sparse(self, f: int) -> bool:
        return isinstance(self.B[f], SparseTransitions)

    def is_sparse_A(self, m: int) -> bool:
        return isinstance(self.A[m], SparseLikelihood)

    def has_counts_A(self, m: int) -> bool:
        """Whether modality ``m`` carries Dirichlet counts (learnable)."""
        return self.A[m].has_counts

    def A_row(self, m: int, o: int) -> np.ndarray:
        """``A[m][o]`` over the live states (the evidence of outcome ``o``)."""
        return self.A[m].row(o)

    def pA_row(self, m: int, o: int) -> np.ndarray:
        """Counts ``pA[m][o]`` over the live states."""
        return self.A[m].counts_row(o)

    # -- live views (copies trimmed to live sizes: references, export, tests) ---------------
    def live_A(self, m: int) -> np.ndarray:
        return self.A[m].to_dense()

    def live_pA(self, m: int) -> np.ndarray | None:
        return self.A[m].counts_dense()

    def live_B(self, f: int) -> np.ndarray:
        return self.B[f].to_dense(self.num_states[f])

    def live_pB(self, f: int) -> np.ndarray | None:
        """Dense transition counts of the live states (None without counts)."""
        B = self.B[f]
        return None if B.counts is None else B.counts_dense(self.num_states[f])

    def live_C(self, m: int) -> np.ndarray:
        return self.C[m][: self.num_obs[m]]

    def live_D(self, f: int) -> np.ndarray:
        return self.D[f][: self.num_states[f]]

    def pose_index(self) -> PoseIndex:
        """Grid hash of the stored poses of the pose factor (cells of one influence radius),
        kept up to date by :meth:`add_state`."""
        pm = self.pose
        if pm is None:
            raise SpecError("this model has no pose factor")
        n = self.num_states[pm.factor]
        if pm.index is None or pm.index.count != n or pm.index.poses is not pm.poses:
            pm.index = PoseIndex(pm.poses, pm.influence_radius, n)
        return pm.index

    def predict(self, f: int, q: np.ndarray, u: int) -> np.ndarray:
        """One-step prediction of factor ``f`` under control ``u``."""
        return self.B[f].predict(q, u)

    # -- growth ----------------------------------------------------------------------------
    def add_state(self, factor: str | int = 0, pose=None, obs_count: float | None = None) -> int:
        """Add one state to a growable factor; returns its index.

        The new state's likelihood columns are uniform over live outcomes with ``obs_count``
        Dirichlet counts per outcome (default ``prior_count``; a sparse likelihood keeps that
        total, ``obs_count x live outcomes``, spread over however many outcomes exist), its transitions self-loop with
        ``prior_count`` counts, the stay control stays the identity, no existing count changes,
        and every column stays normalised. ``pose`` (x, y) is stored when the model has a pose
        factor.
        """
        f = self.factor_index(factor)
        if not self.factors[f].growable:
            raise SpecError(f"factor '{self.factors[f].name}' is not growable")
        s = self.num_states[f]
        if s == self.state_capacity(f):
            self._grow_state_capacity(f, 2 * max(1, s))
        self.num_states[f] = s + 1
        count = self.prior_count if obs_count is None else obs_count
        for m, deps in enumerate(self.A_deps):
            if f in deps:
                self.A[m].add_state(deps.index(f), count)
        self.B[f].add_state(s, self.prior_count)
        self.C_states[f][s] = 0.0
        if self.pose is not None and self.pose.factor == f:
            if pose is None:
                raise SpecError(f"factor '{self.factors[f].name}' has poses: add_state needs pose=")
            self.pose.poses[s] = pose
            if self.pose.index is not None and self.pose.index.count == s:
                self.pose.index.add(s)
        return s

    def add_observation(self, modality: str | int = 0, count: float | None = None) -> int:
        """Add one outcome to a growable modality; returns its index.

        With Dirichlet counts, every live column gains ``count`` (default ``prior_count``) for
        the new outcome and is renormalised from its counts (existing counts unchanged); without
        counts the new outcome starts with probability 0 everywhere. A sparse likelihood spreads
        each column's prior mass over one more outcome instead (O(1), ``count`` does not apply).
        """
        m = self.modality_index(modality)
        if not self.modalities[m].growable:
            raise SpecError(f"modality '{self.modalities[m].name}' is not growable")
        o = self.num_obs[m]
        if o == self.obs_capacity(m):
            self._grow_obs_capacity(m, 2 * max(1, o))
        self.A[m].add_observation(self.prior_count if count is None and not self.is_sparse_A(m) else count)
        self.num_obs[m] = o + 1
        self.C[m][o] = 0.0
        return o

    def _grow_state_capacity(self, f: int, cap: int) -> None:
        self.compile_count += 1
        for m, deps in enumerate(self.A_deps):
            if f in deps:
                self.A[m].grow_states(deps.index(f), cap)
        self.B[f].grow(cap)
        self.D[f] = pad_axis(self.D[f], 0, cap)
        self.C_states[f] = pad_axis(self.C_states[f], 0, cap)
        if self.pose is not None and self.pose.factor == f:
            self.pose.poses = pad_axis(self.pose.poses, 0, cap)
            if self.pose.index is not None:
                self.pose.index.poses = self.pose.poses

    def _grow_obs_capacity(self, m: int, cap: int) -> None:
        self.compile_count += 1
        self.C[m] = pad_axis(self.C[m], 0, cap)
        self.A[m].grow_obs(cap)

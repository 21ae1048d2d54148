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
    """Stored metric pose per state (AIMAPP's B_p) and the action-conditioned pose prediction.

    Attributes
    ----------
    factor : int
        Index of the factor whose states carry poses.
    poses : numpy.ndarray
        ``(capacity, 2)`` float, metres, world frame: the stored pose of each state.
    headings : numpy.ndarray
        ``(num_moves,)`` float radians, the direction of each non-stay control.
    step : float
        Length (metres) of one move.
    influence_radius : float
        Radius (metres) within which a pose observation is matched to a stored pose.
    sigma : float
        Width (metres) of the Gaussian pose likelihood.
    index : PoseIndex or None
        Grid hash of the poses, built on first use by :meth:`Model.pose_index`.
    """

    factor: int
    poses: np.ndarray  # (capacity, 2)
    headings: np.ndarray  # (num_moves,)
    step: float
    influence_radius: float
    sigma: float
    index: PoseIndex | None = field(default=None, repr=False)  # built on first use (Model.pose_index)

    def predict(self, pose: np.ndarray, control: int, stay: int | None) -> np.ndarray:
        """Pose after ``control`` from ``pose``: ``pose + step * (cos h, sin h)``; the stay control keeps it.

        Parameters
        ----------
        pose : numpy.ndarray
            ``(2,)`` float, metres, world frame.
        control : int
            Control index of the pose factor.
        stay : int or None
            Index of the stay control (its heading is skipped in ``headings``), or None.

        Returns
        -------
        numpy.ndarray
            ``(2,)`` float predicted pose (a new array).
        """
        if stay is not None and control == stay:
            return np.asarray(pose, dtype=float).copy()
        h = self.headings[control if stay is None or control < stay else control - 1]
        return np.asarray(pose, dtype=float) + self.step * np.array([np.cos(h), np.sin(h)])


@dataclass
class Model:
    """Arrays of a compiled model (pymdp layout, no batch axis) at capacity, with live sizes.

    Built by :func:`cogmap.genmodel.compile`; grows in place with :meth:`add_state` and
    :meth:`add_observation`.

    Attributes
    ----------
    factors : tuple of Factor
        The hidden-state factors, in array order.
    modalities : tuple of Modality
        The observation modalities, in array order.
    A : list
        One :class:`DenseLikelihood` or :class:`SparseLikelihood` per modality (each owns its counts).
    A_deps : tuple of tuple of int
        Factor indices each modality depends on.
    B : list
        One :class:`DenseTransitions` or :class:`SparseTransitions` per factor (each owns its counts),
        or a :class:`DependentTransitions` for a factor whose next state depends on several factors.
    C : list of numpy.ndarray
        ``(obs_capacity,)`` float log-preferences over the outcomes of each modality.
    D : list of numpy.ndarray
        ``(state_capacity,)`` float initial belief of each factor (live part sums to 1).
    C_states : list of numpy.ndarray
        ``(state_capacity,)`` float log-preferences over the states of each factor.
    num_states : list of int
        Live states per factor.
    num_obs : list of int
        Live outcomes per modality.
    pose : PoseModel or None
        The metric pose model, if the spec had one.
    inductive : InductiveSpec or None
        Settings of the inductive term (Eq. 9 of the AIMAPP paper), if any.
    collision_preference : float or None
        Log-preference against a collision outcome, if any.
    prior_count : float
        Dirichlet count given to new states and outcomes by default.
    compile_count : int
        Number of capacity reallocations so far.
    B_deps : tuple of tuple of int
        Per factor, the factors whose previous states its next state depends on (pymdp's
        ``B_dependencies``); default ``(f,)`` for every factor ``f``.
    """

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
    B_deps: tuple[tuple[int, ...], ...] | None = None

    def __post_init__(self):
        if self.B_deps is None:
            self.B_deps = tuple((f,) for f in range(len(self.B)))
        else:
            self.B_deps = tuple(tuple(int(d) for d in deps) for deps in self.B_deps)

    @property
    def has_B_deps(self) -> bool:
        """Whether some factor's next state depends on other factors' previous states."""
        return any(deps != (f,) for f, deps in enumerate(self.B_deps))

    def refuse_B_deps(self, feature: str, error=SpecError) -> None:
        """Raise ``error`` naming ``feature`` when some factor's transitions depend on other factors.

        Parameters
        ----------
        feature : str
            What does not support such transitions (a scheme, a planner, a backend).
        error : type, optional
            Exception class raised, default :class:`SpecError`.
        """
        if self.has_B_deps:
            multi = {self.factors[f].name: [self.factors[d].name for d in deps]
                     for f, deps in enumerate(self.B_deps) if deps != (f,)}
            raise error(f"{feature} does not support transitions that depend on several factors "
                        f"(B_dependencies {multi}); use a model where each factor depends on itself alone")

    # -- names and shapes ------------------------------------------------------------------
    @property
    def factor_names(self) -> tuple[str, ...]:
        """Names of the factors, in array order."""
        return tuple(f.name for f in self.factors)

    @property
    def modality_names(self) -> tuple[str, ...]:
        """Names of the modalities, in array order."""
        return tuple(m.name for m in self.modalities)

    @property
    def num_controls(self) -> list[int]:
        """Number of controls of each factor."""
        return [f.num_controls for f in self.factors]

    def factor_index(self, name: str | int) -> int:
        """Index of a factor given by name or index.

        Parameters
        ----------
        name : str or int
            Factor name, or an index to check.

        Returns
        -------
        int
            The factor's index.

        Raises
        ------
        SpecError
            If the name is unknown or the index out of range.
        """
        if isinstance(name, int | np.integer):
            if not 0 <= int(name) < len(self.factors):
                raise SpecError(f"factor index {name} out of range (have {len(self.factors)})")
            return int(name)
        try:
            return self.factor_names.index(name)
        except ValueError:
            raise SpecError(f"unknown factor '{name}' (known: {list(self.factor_names)})") from None

    def modality_index(self, name: str | int) -> int:
        """Index of a modality given by name or index.

        Parameters
        ----------
        name : str or int
            Modality name, or an index to check.

        Returns
        -------
        int
            The modality's index.

        Raises
        ------
        SpecError
            If the name is unknown or the index out of range.
        """
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
        """Number of states room is reserved for in factor ``f``.

        Parameters
        ----------
        f : int
            Factor index.

        Returns
        -------
        int
        """
        return self.D[f].shape[0]

    def obs_capacity(self, m: int) -> int:
        """Number of outcomes room is reserved for in modality ``m``.

        Parameters
        ----------
        m : int
            Modality index.

        Returns
        -------
        int
        """
        return self.C[m].shape[0]

    def state_mask(self, f: int) -> np.ndarray:
        """Mask of the live states of factor ``f``.

        Parameters
        ----------
        f : int
            Factor index.

        Returns
        -------
        numpy.ndarray
            ``(state_capacity(f),)`` bool, True for the first ``num_states[f]`` entries.
        """
        mask = np.zeros(self.state_capacity(f), dtype=bool)
        mask[: self.num_states[f]] = True
        return mask

    def obs_mask(self, m: int) -> np.ndarray:
        """Mask of the live outcomes of modality ``m``.

        Parameters
        ----------
        m : int
            Modality index.

        Returns
        -------
        numpy.ndarray
            ``(obs_capacity(m),)`` bool, True for the first ``num_obs[m]`` entries.
        """
        mask = np.zeros(self.obs_capacity(m), dtype=bool)
        mask[: self.num_obs[m]] = True
        return mask

    def is_sparse(self, f: int) -> bool:
        """Whether factor ``f`` has sparse transitions (:class:`SparseTransitions`).

        Parameters
        ----------
        f : int
            Factor index.

        Returns
        -------
        bool
        """
        return isinstance(self.B[f], SparseTransitions)

    def is_sparse_A(self, m: int) -> bool:
        """Whether modality ``m`` has a sparse likelihood (:class:`SparseLikelihood`).

        Parameters
        ----------
        m : int
            Modality index.

        Returns
        -------
        bool
        """
        return isinstance(self.A[m], SparseLikelihood)

    def has_counts_A(self, m: int) -> bool:
        """Whether modality ``m`` carries Dirichlet counts (learnable).

        Parameters
        ----------
        m : int
            Modality index.

        Returns
        -------
        bool
        """
        return self.A[m].has_counts

    def A_row(self, m: int, o: int) -> np.ndarray:
        """``A[m][o]`` over the live states (the evidence of outcome ``o``).

        Parameters
        ----------
        m : int
            Modality index.
        o : int
            Outcome index.

        Returns
        -------
        numpy.ndarray
            Float, shaped as the live states of the modality's dependencies.
        """
        return self.A[m].row(o)

    def pA_row(self, m: int, o: int) -> np.ndarray:
        """Counts ``pA[m][o]`` over the live states.

        Parameters
        ----------
        m : int
            Modality index.
        o : int
            Outcome index.

        Returns
        -------
        numpy.ndarray
            Float counts, shaped as the live states of the modality's dependencies.

        Raises
        ------
        SpecError
            If a dense likelihood has no counts.
        """
        return self.A[m].counts_row(o)

    # -- live views (copies trimmed to live sizes: references, export, tests) ---------------
    def live_A(self, m: int) -> np.ndarray:
        """``A[m]`` trimmed to the live outcomes and states.

        Parameters
        ----------
        m : int
            Modality index.

        Returns
        -------
        numpy.ndarray
            ``(num_obs[m], *live states of its dependencies)`` float, columns sum to 1 (a view for a
            dense likelihood, a new array for a sparse one).
        """
        return self.A[m].to_dense()

    def live_pA(self, m: int) -> np.ndarray | None:
        """Dirichlet counts of ``A[m]`` trimmed to the live part (None for a dense likelihood without counts).

        Parameters
        ----------
        m : int
            Modality index.

        Returns
        -------
        numpy.ndarray or None
            ``(num_obs[m], *live states of its dependencies)`` float.
        """
        return self.A[m].counts_dense()

    def live_B(self, f: int) -> np.ndarray:
        """Dense ``B[f]`` of the live states.

        Parameters
        ----------
        f : int
            Factor index.

        Returns
        -------
        numpy.ndarray
            ``(n, n, num_controls)`` float ``B[next, current, control]`` with ``n = num_states[f]``;
            ``(n, *sizes of B_deps[f], num_controls)`` for a factor that depends on several.
        """
        return self.B[f].to_dense(self.num_states[f])

    def live_pB(self, f: int) -> np.ndarray | None:
        """Dense transition counts of the live states (None without counts).

        Parameters
        ----------
        f : int
            Factor index.

        Returns
        -------
        numpy.ndarray or None
            ``(n, n, num_controls)`` float with ``n = num_states[f]``.
        """
        B = self.B[f]
        return None if B.counts is None else B.counts_dense(self.num_states[f])

    def live_C(self, m: int) -> np.ndarray:
        """Log-preferences over the live outcomes of modality ``m`` (a view).

        Parameters
        ----------
        m : int
            Modality index.

        Returns
        -------
        numpy.ndarray
            ``(num_obs[m],)`` float.
        """
        return self.C[m][: self.num_obs[m]]

    def live_D(self, f: int) -> np.ndarray:
        """Initial belief over the live states of factor ``f`` (a view).

        Parameters
        ----------
        f : int
            Factor index.

        Returns
        -------
        numpy.ndarray
            ``(num_states[f],)`` float.
        """
        return self.D[f][: self.num_states[f]]

    def pose_index(self) -> PoseIndex:
        """Grid hash of the stored poses of the pose factor (cells of one influence radius).

        Built on first use and kept up to date by :meth:`add_state`.

        Returns
        -------
        PoseIndex

        Raises
        ------
        SpecError
            If the model has no pose factor.
        """
        pm = self.pose
        if pm is None:
            raise SpecError("this model has no pose factor")
        n = self.num_states[pm.factor]
        if pm.index is None or pm.index.count != n or pm.index.poses is not pm.poses:
            pm.index = PoseIndex(pm.poses, pm.influence_radius, n)
        return pm.index

    def predict(self, f: int, q: np.ndarray, u: int) -> np.ndarray:
        """One-step prediction of factor ``f`` under control ``u``.

        Parameters
        ----------
        f : int
            Factor index.
        q : numpy.ndarray
            ``(n,)`` float belief over the first ``n`` states.
        u : int
            Control index.

        Returns
        -------
        numpy.ndarray
            ``(n,)`` float predicted belief.
        """
        return self.B[f].predict(q, u)

    # -- growth ----------------------------------------------------------------------------
    def add_state(self, factor: str | int = 0, pose=None, obs_count: float | None = None) -> int:
        """Add one state to a growable factor.

        The new state's likelihood columns are uniform over live outcomes with ``obs_count``
        Dirichlet counts per outcome (default ``prior_count``; a sparse likelihood keeps that
        total, ``obs_count x live outcomes``, spread over however many outcomes exist), its transitions
        self-loop with ``prior_count`` counts, the stay control stays the identity, no existing count
        changes, and every column stays normalised. Capacity doubles when full.

        Parameters
        ----------
        factor : str or int, optional
            Factor name or index, default 0.
        pose : array_like, optional
            ``(2,)`` float (x, y) in metres, required when the factor has poses.
        obs_count : float, optional
            Dirichlet count per live outcome in the new likelihood columns; default ``prior_count``.

        Returns
        -------
        int
            Index of the new state.

        Raises
        ------
        SpecError
            If the factor is unknown or not growable, or has poses and ``pose`` is missing.
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
        """Add one outcome to a growable modality.

        With Dirichlet counts, every live column gains ``count`` (default ``prior_count``) for
        the new outcome and is renormalised from its counts (existing counts unchanged); without
        counts the new outcome starts with probability 0 everywhere. A sparse likelihood spreads
        each column's prior mass over one more outcome instead (O(1), ``count`` does not apply).
        The new outcome's preference is 0. Capacity doubles when full.

        Parameters
        ----------
        modality : str or int, optional
            Modality name or index, default 0.
        count : float, optional
            Dirichlet count of the new outcome in every live column (dense likelihoods only).

        Returns
        -------
        int
            Index of the new outcome.

        Raises
        ------
        SpecError
            If the modality is unknown or not growable, or ``count`` is given for a sparse likelihood.
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

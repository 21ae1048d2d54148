"""Declarative generative-model specifications.

A user writes a :class:`ModelSpec` out of named factors and modalities; :func:`compile`
(in ``compile.py``) validates it once and turns it into a :class:`~.model.Model` of arrays.

Conventions follow pymdp 1.0 without the batch axis:

* ``A[m]`` has shape ``(num_obs[m], *num_states[deps[m]])`` and each column sums to 1.
* ``B[f]`` has shape ``(num_states[f], num_states[f], num_controls[f])``; ``B[f][:, s, u]``
  is the distribution of the next state given state ``s`` and control ``u``. A factor with
  ``depends_on`` (pymdp's ``B_dependencies``) has ``B[f]`` shaped
  ``(num_states[f], *num_states[depends_on], num_controls[f])``.
  For large topological maps a :class:`SparseB` (padded successor lists) may be given instead.
  A modality over one growable factor may be a :class:`SparseA` (counts only).
* ``C[m]`` are log-preferences over outcomes (unnormalised, added to the expected utility).
* ``D[f]`` is the initial belief.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from .numerics import normalise  # noqa: F401  (re-exported: cogmap.genmodel.spec.normalise)


class SpecError(ValueError):
    """A model specification or saved model is invalid. The message names the part and problem."""


@dataclass(frozen=True)
class Factor:
    """A hidden-state factor.

    Attributes
    ----------
    name : str
        Unique name, used as the key of ``A``/``B``/``D`` tables in :class:`ModelSpec`.
    size : int
        Initial number of states.
    num_controls : int
        Number of controls (actions) acting on the factor, default 1.
    growable : bool
        Whether states can be added after compilation.
    capacity : int or None
        Reserved room for growth; defaults to the next power of two above ``size`` when ``growable``.
    stay : int or None
        The control index that is structurally the identity (never learned), or None.
    control_names : tuple of str or None
        Optional names of the controls.
    depends_on : tuple of str or None
        Names of the factors whose previous states the next state of this factor depends on (pymdp
        1.0's ``B_dependencies``); the factor itself must be among them. ``B`` is then shaped
        ``(size, *sizes of depends_on, num_controls)``. None (default) means the factor alone,
        ``B`` shaped ``(size, size, num_controls)``. Dense, non-growable factors only.
    """

    name: str
    size: int
    num_controls: int = 1
    growable: bool = False
    capacity: int | None = None
    stay: int | None = None
    control_names: tuple[str, ...] | None = None
    depends_on: tuple[str, ...] | None = None


@dataclass(frozen=True)
class Modality:
    """An observation modality depending on the named factors.

    Attributes
    ----------
    name : str
        Unique name, the key of ``A``/``C``/``pA`` tables in :class:`ModelSpec`.
    size : int
        Initial number of outcomes.
    depends_on : tuple of str
        Names of the factors the outcome depends on (the state axes of ``A``, in order).
    growable : bool
        Whether outcomes can be added after compilation.
    capacity : int or None
        Reserved room for growth (as for :class:`Factor`).
    """

    name: str
    size: int
    depends_on: tuple[str, ...]
    growable: bool = False
    capacity: int | None = None


@dataclass(frozen=True)
class SparseB:
    """Transitions stored as padded successor lists.

    ``succ[s, u, k]`` is a successor of ``s`` under control ``u`` with probability ``prob[s, u, k]``
    (each ``prob[s, u, :]`` sums to 1; empty slots have probability 0). The cost of a prediction grows
    with the number of edges, not with states squared.

    Attributes
    ----------
    succ : array_like
        ``(num_states, num_controls, slots)`` int successor states.
    prob : array_like
        ``(num_states, num_controls, slots)`` float probabilities.
    counts : array_like or None
        Dirichlet counts in the same layout (no dense ``(n, n, u)`` pB needed), or None.
    """

    succ: Any
    prob: Any
    counts: Any = None  # Dirichlet counts in the same layout (no dense (n, n, u) pB needed)


@dataclass(frozen=True)
class SparseA:
    """A likelihood over one factor given by its Dirichlet counts, never as a dense array.

    Column ``s`` has a symmetric prior of total concentration ``prior[s]`` spread evenly over the
    outcomes, plus learned ``counts`` at the ``(outcomes[i], states[i])`` pairs. ``A`` is the
    normalised counts. Growth and learning cost O(1) per step
    (:class:`~cogmap.genmodel.likelihood.SparseLikelihood`).

    Attributes
    ----------
    prior : array_like
        ``(num_states,)`` float, total prior concentration of each column.
    outcomes : array_like
        ``(k,)`` int outcome index of each learned count.
    states : array_like
        ``(k,)`` int state index of each learned count.
    counts : array_like
        ``(k,)`` float learned counts.
    """

    prior: Any
    outcomes: Any = ()
    states: Any = ()
    counts: Any = ()


@dataclass(frozen=True)
class PoseSpec:
    """AIMAPP's metric pose model for one factor (B_p and A_p).

    A move predicts ``pose + step * (cos h, sin h)``; a pose observation is the index of the stored
    pose within ``influence_radius``.

    Attributes
    ----------
    factor : str
        Name of the factor whose states carry poses.
    poses : array_like
        ``(size, 2)`` float, metres, world frame: the stored pose of each initial state.
    headings : array_like
        ``(num_moves,)`` float radians, one per non-stay control.
    step : float
        Length (metres) of one move, default 1.
    influence_radius : float
        Radius (metres) of a state's neighbourhood, default 1 (Table 6 of the AIMAPP paper: 1 m
        small, 2 m large environments).
    sigma : float or None
        Width (metres) of the Gaussian pose likelihood; defaults to ``influence_radius / 2``.
    """

    factor: str
    poses: Any
    headings: Any
    step: float = 1.0
    influence_radius: float = 1.0
    sigma: float | None = None  # width of the pose likelihood; defaults to influence_radius / 2


@dataclass(frozen=True)
class InductiveSpec:
    """Settings of the inductive term H (Eq. 9 of the AIMAPP paper).

    Attributes
    ----------
    threshold : float
        Transition probability in [0, 1] above which a move counts as believed possible, default 0.5.
    depth : int
        Horizon in believed-possible moves: goals farther away are ignored; at least 1, default 10
        (also the default MCTS depth of :func:`cogmap.planning.decide`).
    weight : float
        Weight of the term in the expected free energy, default 1.
    """

    threshold: float = 0.5
    depth: int = 10
    weight: float = 1.0


@dataclass
class ModelSpec:
    """A generative model as named factor specifications (see the module docstring for array layouts).

    Attributes
    ----------
    factors : list of Factor
        Hidden-state factors.
    modalities : list of Modality
        Observation modalities.
    A : dict
        Modality name -> ``(size, *sizes of depends_on)`` float likelihood (columns sum to 1) or a
        :class:`SparseA`.
    B : dict
        Factor name -> ``(size, size, num_controls)`` float transitions ``B[next, current, control]``
        or a :class:`SparseB`.
    C : dict
        Modality name -> ``(size,)`` float log-preferences over outcomes (default 0).
    D : dict
        Factor name -> ``(size,)`` float initial belief, sums to 1 (default uniform).
    pA : dict
        Modality name -> Dirichlet counts shaped as ``A`` (makes the likelihood learnable).
    pB : dict
        Factor name -> Dirichlet counts shaped as dense ``B``.
    C_states : dict
        Factor name -> ``(size,)`` float log-preferences over states (default 0).
    pose : PoseSpec or None
        Metric pose model of one factor.
    inductive : InductiveSpec or None
        Settings of the inductive term.
    collision_preference : float or None
        Log-preference against a collision outcome.
    """

    factors: list[Factor]
    modalities: list[Modality]
    A: dict[str, Any]
    B: dict[str, Any]
    C: dict[str, Any] = field(default_factory=dict)
    D: dict[str, Any] = field(default_factory=dict)
    pA: dict[str, Any] = field(default_factory=dict)
    pB: dict[str, Any] = field(default_factory=dict)
    C_states: dict[str, Any] = field(default_factory=dict)
    pose: PoseSpec | None = None
    inductive: InductiveSpec | None = None
    collision_preference: float | None = None  # log-preference against a collision outcome




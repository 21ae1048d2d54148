"""Declarative generative-model specifications.

A user writes a :class:`ModelSpec` out of named factors and modalities; :func:`compile`
(in ``compile.py``) validates it once and turns it into a :class:`~.model.Model` of arrays.

Conventions follow pymdp 1.0 without the batch axis:

* ``A[m]`` has shape ``(num_obs[m], *num_states[deps[m]])`` and each column sums to 1.
* ``B[f]`` has shape ``(num_states[f], num_states[f], num_controls[f])``; ``B[f][:, s, u]``
  is the distribution of the next state given state ``s`` and control ``u``.
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

    ``capacity`` reserves room for growth (defaults to the next power of two above ``size``
    when ``growable``); ``stay`` names the control index that is structurally the identity
    (never learned), or ``None``.
    """

    name: str
    size: int
    num_controls: int = 1
    growable: bool = False
    capacity: int | None = None
    stay: int | None = None
    control_names: tuple[str, ...] | None = None


@dataclass(frozen=True)
class Modality:
    """An observation modality depending on the named factors."""

    name: str
    size: int
    depends_on: tuple[str, ...]
    growable: bool = False
    capacity: int | None = None


@dataclass(frozen=True)
class SparseB:
    """Transitions stored as padded successor lists: ``succ[s, u, k]`` with probability
    ``prob[s, u, k]`` (each ``prob[s, u, :]`` sums to 1; empty slots have probability 0).

    Cost of a prediction grows with the number of edges, not with states squared.
    """

    succ: Any
    prob: Any
    counts: Any = None  # Dirichlet counts in the same layout (no dense (n, n, u) pB needed)


@dataclass(frozen=True)
class SparseA:
    """A likelihood over one factor given by its Dirichlet counts, never as a dense array:
    column ``s`` has a symmetric prior of total concentration ``prior[s]`` spread evenly over
    the outcomes, plus learned ``counts`` at the ``(outcomes[i], states[i])`` pairs. ``A`` is
    the normalised counts. Growth and learning cost O(1) per step
    (:class:`~cogmap.genmodel.likelihood.SparseLikelihood`)."""

    prior: Any
    outcomes: Any = ()
    states: Any = ()
    counts: Any = ()


@dataclass(frozen=True)
class PoseSpec:
    """AIMAPP's metric pose model for one factor (B_p and A_p).

    ``poses[s]`` is the stored 2-D pose of state ``s``; ``headings`` are the action directions
    (radians, one per non-stay control); a move predicts ``pose + step * (cos h, sin h)``.
    A pose observation is the index of the stored pose within ``influence_radius``.
    """

    factor: str
    poses: Any
    headings: Any
    step: float = 1.0
    influence_radius: float = 1.0
    sigma: float | None = None  # width of the pose likelihood; defaults to influence_radius / 2


@dataclass(frozen=True)
class InductiveSpec:
    """Settings of the inductive term H (Eq. 9): reachability threshold, depth, weight."""

    threshold: float = 0.5
    depth: int = 10
    weight: float = 1.0


@dataclass
class ModelSpec:
    """A generative model as named factor specifications (see module docstring)."""

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




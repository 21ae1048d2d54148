"""Expected free energy (Eq. 5-6, Table 1) as small composable terms.

A *term* is a pure function ``term(ctx) -> value`` returning one number per candidate (shape
``(K,)``) for one planning step; ``ctx`` is a step context (:class:`~.context.DenseStep` or
:class:`~.context.LocalStep`) exposing predicted beliefs and the model arrays restricted to the
states the candidates can reach. Values follow the sign of pymdp's ``neg_efe``: information gain
and expected log-preferences are *added* (higher is better).

:func:`objective` combines weighted terms, Optax-``chain`` style, into a callable returning the
per-step expected free energy ``G = -sum_i w_i * term_i(ctx)`` (lower is better). Any subset of
terms can be combined; :func:`exploration` and :func:`goal` are the two presets of the paper.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from cogmap.genmodel import contracts
from cogmap.genmodel.dirichlet import novelty
from cogmap.genmodel.numerics import LOG_FLOOR, xlogx
from cogmap.genmodel.registry import check_entry, check_name

EPS = LOG_FLOOR  # the shared log floor (cogmap.genmodel.numerics)

Term = Callable[[object], np.ndarray]


# -- numerics shared by the backends -------------------------------------------------------
def entropy(p: np.ndarray, axis: int = -1) -> np.ndarray:
    """Shannon entropy along ``axis``."""
    return -xlogx(p).sum(axis=axis)


def novelty_weights(counts: np.ndarray, axis: int = 0) -> np.ndarray:
    """Expected information gain weights of Dirichlet ``counts`` (columns along ``axis``).

    ``W = ln a0 - ln a + psi(a + 1) - psi(a0 + 1)`` (exact form of the parameter information
    gain, Da Costa et al. 2020, D.15), zero where a count is zero. The information gain about
    the parameters of a column is the expectation of ``W`` under the predicted joint of the
    column's outcome and its conditioning states.
    """
    a = np.maximum(counts, EPS)
    return np.where(counts > 0, novelty(a, a.sum(axis=axis, keepdims=True)), 0.0)


# -- the six terms of Eq. 6 (plus the inductive term of Eq. 9) ------------------------------
def state_info_gain(ctx) -> np.ndarray:
    """Epistemic value about states: ``sum_m H[Q(o_m)] - E_Q(s)[H[P(o_m|s)]]``.

    Parameters
    ----------
    ctx : DenseStep or LocalStep
        Step context of ``K`` candidates (:mod:`cogmap.planning.context`).

    Returns
    -------
    numpy.ndarray
        ``(K,)`` float, nats; higher is better (pymdp's ``neg_efe`` sign).

    Notes
    -----
    The state information gain of Eq. (6) / Table 1 of the AIMAPP paper.
    """
    out = np.zeros(ctx.num_candidates)
    for h, amb in zip(ctx.outcome_entropy, ctx.ambiguity, strict=True):
        out += h - amb
    return out


def _sum_present(values, n: int) -> np.ndarray:
    """Sum of the per-modality (or per-factor) values that exist (``None``: no counts)."""
    out = np.zeros(n)
    for v in values:
        if v is not None:
            out += v
    return out


def a_novelty(ctx) -> np.ndarray:
    """Information gain about likelihood parameters (from ``pA``); zero without counts.

    Parameters
    ----------
    ctx : DenseStep or LocalStep
        Step context of ``K`` candidates (:mod:`cogmap.planning.context`).

    Returns
    -------
    numpy.ndarray
        ``(K,)`` float, nats; higher is better (pymdp's ``neg_efe`` sign).

    Notes
    -----
    Part of the parameter information gain of Eq. (6) / Table 1 of the AIMAPP paper.
    """
    return _sum_present(ctx.a_novelty, ctx.num_candidates)


def b_novelty(ctx) -> np.ndarray:
    """Information gain about transition parameters (from ``pB``); zero without counts.

    Parameters
    ----------
    ctx : DenseStep or LocalStep
        Step context of ``K`` candidates (:mod:`cogmap.planning.context`).

    Returns
    -------
    numpy.ndarray
        ``(K,)`` float, nats; higher is better (pymdp's ``neg_efe`` sign).

    Notes
    -----
    Part of the parameter information gain of Eq. (6) / Table 1 of the AIMAPP paper.
    """
    return _sum_present(ctx.b_novelty, ctx.num_candidates)


def param_info_gain(ctx) -> np.ndarray:
    """Epistemic value about parameters: :func:`a_novelty` + :func:`b_novelty`.

    Parameters
    ----------
    ctx : DenseStep or LocalStep
        Step context of ``K`` candidates (:mod:`cogmap.planning.context`).

    Returns
    -------
    numpy.ndarray
        ``(K,)`` float, nats; higher is better (pymdp's ``neg_efe`` sign).

    Notes
    -----
    The parameter information gain of Eq. (6) / Table 1 of the AIMAPP paper.
    """
    return a_novelty(ctx) + b_novelty(ctx)


def sensed_info_gain(ctx) -> np.ndarray:
    """Information gain on states and parameters, weighted by what the LiDAR has not yet sensed:
    ``(state_info_gain + param_info_gain) * E_Q(s)[w(s)]`` with ``w(s)`` in [0, 1] the fraction
    of the view from state ``s`` that is still unseen (``ctx.view``). The observation a state
    would yield carries information about the map only where its view reaches unseen space, so a
    state whose surroundings the LiDAR has already swept promises (almost) nothing. Without a
    view weight (no scans) this is the plain epistemic value of Eq. 6."""
    gain = state_info_gain(ctx) + param_info_gain(ctx)
    return gain if ctx.view is None else gain * ctx.view


def observation_preference(ctx) -> np.ndarray:
    """Expected log-preference over outcomes, ``sum_m Q(o_m) . C_m``.

    Parameters
    ----------
    ctx : DenseStep or LocalStep
        Step context of ``K`` candidates (:mod:`cogmap.planning.context`).

    Returns
    -------
    numpy.ndarray
        ``(K,)`` float, nats; higher is better (pymdp's ``neg_efe`` sign).

    Notes
    -----
    The preference (utility) term of Eq. (6) / Table 1 of the AIMAPP paper.
    """
    out = np.zeros(ctx.num_candidates)
    for u in ctx.outcome_utility:
        out += u
    return out


def state_preference(ctx) -> np.ndarray:
    """Expected log-preference over states, ``sum_f Q(s_f) . C_states_f``.

    Parameters
    ----------
    ctx : DenseStep or LocalStep
        Step context of ``K`` candidates (:mod:`cogmap.planning.context`).

    Returns
    -------
    numpy.ndarray
        ``(K,)`` float, nats; higher is better (pymdp's ``neg_efe`` sign).

    Notes
    -----
    A preference term of Eq. (6) / Table 1 of the AIMAPP paper, over states.
    """
    out = np.zeros(ctx.num_candidates)
    for qs, c in zip(ctx.qs, ctx.C_states, strict=True):
        if c is not None:
            out += qs @ c
    return out


def position_preference(ctx) -> np.ndarray:
    """Expected Gaussian log-preference of the predicted state's stored pose around a target pose.

    ``E_Q(s)[-|pose(s) - target|^2 / (2 sigma^2)]`` with poses in metres; zero without a target pose.

    Parameters
    ----------
    ctx : DenseStep or LocalStep
        Step context of ``K`` candidates (:mod:`cogmap.planning.context`).

    Returns
    -------
    numpy.ndarray
        ``(K,)`` float, nats; higher is better (pymdp's ``neg_efe`` sign).

    Notes
    -----
    The preference over positions of Eq. (6) / Table 1 of the AIMAPP paper.
    """
    if ctx.target_pose is None or ctx.poses is None:
        return np.zeros(ctx.num_candidates)
    d2 = ((ctx.poses - np.asarray(ctx.target_pose, dtype=float)) ** 2).sum(axis=1)
    return ctx.qs[ctx.pose_factor] @ (-0.5 * d2 / ctx.pose_sigma**2)


def collision(ctx) -> np.ndarray:
    """Expected log-preference of the collision outcome: ``P(collision) * ln P~(collision)``.

    ``ln P~(no collision) = 0``. ``P(collision)`` comes from the binary per-direction obstacle
    signal (one flag per control) at the first step, zero afterwards; zero without a signal.

    Parameters
    ----------
    ctx : DenseStep or LocalStep
        Step context of ``K`` candidates (:mod:`cogmap.planning.context`).

    Returns
    -------
    numpy.ndarray
        ``(K,)`` float, nats; higher is better (pymdp's ``neg_efe`` sign).

    Notes
    -----
    The collision term of Eq. (6) / Table 1 of the AIMAPP paper.
    """
    if ctx.collision is None:
        return np.zeros(ctx.num_candidates)
    return ctx.collision * ctx.collision_pref


def inductive(ctx) -> np.ndarray:
    """Inductive value H (Eq. 9): probability that the step moves to a state strictly closer
    (in believed-possible transitions) to a preferred state, or stays on one, counted only
    when the goal is within the inductive horizon. Silent (zero) without a goal."""
    if ctx.closer is None:
        return np.zeros(ctx.num_candidates)
    return ctx.closer


ALL_TERMS: dict[str, Term] = {
    "state_info_gain": state_info_gain,
    "param_info_gain": param_info_gain,
    "a_novelty": a_novelty,
    "b_novelty": b_novelty,
    "collision": collision,
    "observation_preference": observation_preference,
    "position_preference": position_preference,
    "state_preference": state_preference,
    "inductive": inductive,
    "sensed_info_gain": sensed_info_gain,
}


#: terms whose value is information: gained once, so not counted again on a revisit (MCTS)
EPISTEMIC = (state_info_gain, param_info_gain, a_novelty, b_novelty, sensed_info_gain)

# -- user terms ------------------------------------------------------------------------------
_USER_TERMS: dict[str, Term] = {}
_USER_EPISTEMIC: dict[str, Term] = {}


def register_term(name: str, term: Term, overwrite: bool = False, *, epistemic: bool = False) -> Term:
    """Make ``term`` usable by name in :func:`objective` (and so in every planner).

    Parameters
    ----------
    name : str
        The name ``objective({name: weight})`` will accept.
    term : callable
        ``term(ctx) -> (K,)`` with the contract of the built-in terms (module docstring):
        higher is better, the objective subtracts ``weight * term(ctx)`` from ``G``.
    overwrite : bool
        Replace a term registered under ``name`` (built-in terms cannot be replaced).
    epistemic : bool
        The value is information: counted once per imagined path when MCTS runs with
        ``count_information_once`` (see :meth:`Objective.split`).

    Returns
    -------
    callable
        ``term``.

    Raises
    ------
    ValueError
        Empty name, a built-in name (:data:`ALL_TERMS`), or a name already registered without
        ``overwrite``.
    TypeError
        ``term`` is not callable or cannot be called as ``term(ctx)``
        (:class:`cogmap.genmodel.contracts.EFETerm`).
    """
    check_name("register_term", name)
    if name in ALL_TERMS:
        raise ValueError(f"register_term: '{name}' is a built-in EFE term; choose another name")
    check_entry("register_term", "term", name, term, _USER_TERMS, ALL_TERMS, overwrite,
                expected="a callable term(ctx) -> (K,)", protocol=contracts.EFETerm)
    _USER_TERMS[name] = term
    _USER_EPISTEMIC.pop(name, None)
    if epistemic:
        _USER_EPISTEMIC[name] = term
    return term


def unregister_term(name: str) -> None:
    """Remove a term added with :func:`register_term`.

    Parameters
    ----------
    name : str
        The registered name.

    Raises
    ------
    KeyError
        No registered term has that name (the message lists the registered ones).
    """
    if name not in _USER_TERMS:
        raise KeyError(f"no registered EFE term named {name!r} (registered: {sorted(_USER_TERMS)})")
    del _USER_TERMS[name]
    _USER_EPISTEMIC.pop(name, None)


def available_terms() -> tuple[str, ...]:
    """Names :func:`objective` accepts.

    Returns
    -------
    tuple of str
        Sorted names of the built-in and the registered terms.
    """
    return tuple(sorted({*ALL_TERMS, *_USER_TERMS}))


def is_builtin(term: Term) -> bool:
    """Whether ``term`` is one of this module's terms.

    The planners prepare exactly what the built-in terms read; a user term may read any
    attribute of the step context, so with one in an objective everything is prepared.

    Parameters
    ----------
    term : callable
        A term function.

    Returns
    -------
    bool
        True for a term of :data:`ALL_TERMS`.
    """
    return term in ALL_TERMS.values()


def is_epistemic(term: Term) -> bool:
    """Whether ``term``'s value is information.

    Parameters
    ----------
    term : callable
        A term function.

    Returns
    -------
    bool
        True for the built-in epistemic terms (:data:`EPISTEMIC`) and terms registered with
        ``epistemic=True``; :meth:`Objective.split` leaves those out of a revisited step's value.
    """
    return term in EPISTEMIC or term in _USER_EPISTEMIC.values()


# -- combinator ------------------------------------------------------------------------------
@dataclass(frozen=True)
class Objective:
    """Weighted sum of EFE terms; calling it on a step context returns the per-step EFE per candidate.

    ``objective(ctx)`` returns ``G = -sum_i w_i * term_i(ctx)``, ``(K,)`` float, lower is better;
    terms with weight 0 are not evaluated.

    Attributes
    ----------
    terms : tuple of (callable, float)
        ``(term, weight)`` pairs; a term maps a step context to a ``(K,)`` array.
    """

    terms: tuple[tuple[Term, float], ...]

    def __call__(self, ctx) -> np.ndarray:
        g = np.zeros(ctx.num_candidates)
        for term, w in self.terms:
            if w != 0.0:
                g -= w * term(ctx)
        return g

    def split(self, ctx) -> tuple[np.ndarray, np.ndarray]:
        """``(G, G without the epistemic terms)`` per candidate.

        The second is the value of a step whose information has already been gained earlier on the same
        imagined path (MCTS revisits).

        Parameters
        ----------
        ctx : DenseStep or LocalStep
            Step context of ``K`` candidates.

        Returns
        -------
        G : numpy.ndarray
            ``(K,)`` float expected free energy.
        G_known : numpy.ndarray
            ``(K,)`` float, the same without the terms in ``EPISTEMIC``.
        """
        g = np.zeros(ctx.num_candidates)
        g_known = np.zeros(ctx.num_candidates)
        for term, w in self.terms:
            if w != 0.0:
                v = w * term(ctx)
                g -= v
                if not is_epistemic(term):
                    g_known -= v
        return g, g_known

    def breakdown(self, ctx) -> dict[str, np.ndarray]:
        """Weighted contribution of every term to ``G`` (same sign as ``G``).

        Parameters
        ----------
        ctx : DenseStep or LocalStep
            Step context of ``K`` candidates.

        Returns
        -------
        dict of str to numpy.ndarray
            Term name -> ``(K,)`` float ``-w * term(ctx)``.
        """
        return {getattr(t, "__name__", repr(t)): -w * t(ctx) for t, w in self.terms}

    @property
    def names(self) -> tuple[str, ...]:
        """Names of the terms, in order."""
        return tuple(getattr(t, "__name__", repr(t)) for t, _ in self.terms)

    def uses(self, term: Term) -> bool:
        """Whether ``term`` is among the terms with a nonzero weight.

        Parameters
        ----------
        term : callable
            An EFE term function.

        Returns
        -------
        bool
        """
        return any(t is term and w != 0.0 for t, w in self.terms)


def objective(terms: Sequence[tuple[Term | str, float]] | dict) -> Objective:
    """Build an objective from ``[(term, weight), ...]`` (terms as functions or names), Optax-``chain`` style.

    Parameters
    ----------
    terms : sequence of (callable or str, float) or dict
        Term functions or names (the built-in ones of ``ALL_TERMS`` and those added with
        :func:`register_term`) with their weights; a dict ``{term: weight}`` works too.

    Returns
    -------
    Objective

    Raises
    ------
    KeyError
        For an unknown term name.
    TypeError
        For a term that is not callable.
    """
    items = terms.items() if isinstance(terms, dict) else terms
    out = []
    for t, w in items:
        if isinstance(t, str):
            if t in ALL_TERMS:
                t = ALL_TERMS[t]
            elif t in _USER_TERMS:
                t = _USER_TERMS[t]
            else:
                raise KeyError(f"unknown EFE term '{t}' (known: {list(available_terms())})")
        if not callable(t):
            raise TypeError(f"EFE term {t!r} is not callable")
        out.append((t, float(w)))
    return Objective(tuple(out))


def exploration(collision_weight: float = 1.0, epistemic_weight: float = 1.0) -> Objective:
    """Exploration mode: information gain on states and parameters, plus collision.

    Parameters
    ----------
    collision_weight : float, optional
        Weight of :func:`collision`, default 1.
    epistemic_weight : float, optional
        Weight of :func:`state_info_gain` and of :func:`param_info_gain`, default 1.

    Returns
    -------
    Objective
    """
    return objective(
        [
            (state_info_gain, epistemic_weight),
            (param_info_gain, epistemic_weight),
            (collision, collision_weight),
        ]
    )


def sensed_exploration(
    collision_weight: float = 1.0, epistemic_weight: float = 1.0, inductive_weight: float = 1.0
) -> Objective:
    """Exploration that knows what the LiDAR has sensed: the information gain weighted by the
    unseen part of each state's view (:func:`sensed_info_gain`), the inductive term (Eq. 9)
    with the states that still promise information as its preferred states (so MCTS is pulled
    toward unexplored parts beyond its depth), and collision."""
    return objective(
        [
            (sensed_info_gain, epistemic_weight),
            (inductive, inductive_weight),
            (collision, collision_weight),
        ]
    )


def goal(
    goal_weight: float = 10.0, inductive_weight: float = 1.0, collision_weight: float = 1.0
) -> Objective:
    """Goal mode: observation, position and state preferences, the inductive term and collision.

    Parameters
    ----------
    goal_weight : float, optional
        Weight of the three preference terms, default 10 (Table 6 of the AIMAPP paper).
    inductive_weight : float, optional
        Weight of the inductive term (Eq. 9), default 1.
    collision_weight : float, optional
        Weight of :func:`collision`, default 1.

    Returns
    -------
    Objective
    """
    return objective(
        [
            (observation_preference, goal_weight),
            (position_preference, goal_weight),
            (state_preference, goal_weight),
            (inductive, inductive_weight),
            (collision, collision_weight),
        ]
    )


def full(goal_weight: float = 10.0, inductive_weight: float = 1.0) -> Objective:
    """All six terms of Eq. (6) of the AIMAPP paper plus the inductive term (Eq. 9).

    Information gains and collision have weight 1.

    Parameters
    ----------
    goal_weight : float, optional
        Weight of the three preference terms, default 10.
    inductive_weight : float, optional
        Weight of the inductive term, default 1.

    Returns
    -------
    Objective
    """
    return objective(
        [
            (state_info_gain, 1.0),
            (param_info_gain, 1.0),
            (collision, 1.0),
            (observation_preference, goal_weight),
            (position_preference, goal_weight),
            (state_preference, goal_weight),
            (inductive, inductive_weight),
        ]
    )


def pymdp_like(
    use_utility: bool = True, use_states_info_gain: bool = True, use_param_info_gain: bool = False
) -> Objective:
    """The terms pymdp 1.0 sums in ``neg_efe`` (for cross-checks)."""
    return objective(
        [
            (state_info_gain, float(use_states_info_gain)),
            (observation_preference, float(use_utility)),
            (param_info_gain, float(use_param_info_gain)),
        ]
    )

"""Shared pieces of every inference scheme: the result type, input checking and evidence.

Every scheme has the call

    posterior, info = scheme(model, prior, observations, actions=None, **options)

* ``prior``: one belief per factor over the states at the first time step, *before* that
  step's observation (``model.D`` or a predicted empirical prior). Each entry has the factor's
  live length (or its capacity, with zero mass on not-yet-live states) and sums to 1.
* ``observations``: a sequence over time (length ``T >= 1``). Each step is either

  - a list/tuple with one entry per modality, optionally followed by one more entry holding
    the metric pose ``(x, y)`` when the model has a pose factor, or
  - a dict keyed by modality name (or index), plus the key ``"pose"`` for the metric pose.
    Modalities absent from the dict did not report.

  Each modality entry is an outcome index, a probability vector over the live outcomes
  (treated as soft evidence: likelihood ``sum_o p(o) A[o, s]``) or ``None`` (missing: no
  evidence). The metric pose contributes the likelihood ``exp(-|p - poses[s]|^2 / (2 sigma^2))``
  over the live states of the pose factor (the Gaussian's constant ``2 pi sigma^2`` is left
  out, so free energies with pose evidence are defined up to that constant).
* ``actions``: ``T - 1`` control tuples (one integer control per factor; a bare int is accepted
  for a single factor; floats, strings and bools are refused). May be omitted when every factor
  has a single control.

``posterior`` is the per-factor list of beliefs (live length) at the last step and ``info`` an
:class:`InferenceInfo`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from cogmap.genmodel.compile import real_array
from cogmap.genmodel.numerics import LOG_FLOOR, floor_log, softmax, xlogx_sum  # noqa: F401  (re-exported)

POSE_KEY = "pose"
ATOL = 1e-6
#: floor used inside logarithms by the variational schemes (the same floor as pymdp 1.0)



class InferenceError(ValueError):
    """Bad input to an inference scheme; the message names the argument and the problem."""


class InferenceInfo(NamedTuple):
    """What a scheme reports beside the posterior.

    Attributes
    ----------
    free_energy : float
        Variational free energy of the last step in nats (for exact Bayes,
        ``-log p(o_T | o_<T)``).
    history : tuple
        Per-time tuples of per-factor beliefs (filtered or smoothed, as the scheme documents).
    iterations : int
        Update sweeps used at the last step.
    total_free_energy : float or None
        Free energy of the whole sequence in nats (``-log p(o_1:T)`` for exact Bayes), or None.
    """

    free_energy: float
    history: tuple
    iterations: int
    total_free_energy: float | None = None


@dataclass(frozen=True)
class Evidence:
    """Likelihood of one observation over the live states of the factors ``deps``.

    The true likelihood is ``lik * exp(log_scale)``; ``lik`` is rescaled to max 1 where that
    avoids underflow (pose evidence far from every stored pose).

    Attributes
    ----------
    deps : tuple of int
        Factor indices the likelihood depends on (the axes of ``lik``).
    lik : numpy.ndarray
        Float likelihood, shaped as the live states of ``deps``.
    log_scale : float
        Log of the factor ``lik`` was divided by (0 when not rescaled).
    name : str
        Name of the modality (or ``"pose"``) it came from.
    """

    deps: tuple[int, ...]
    lik: np.ndarray
    log_scale: float = 0.0
    name: str = ""


@dataclass(frozen=True)
class Problem:
    """Checked inputs of a scheme on live slices, as built by :func:`prepare`.

    Attributes
    ----------
    sizes : tuple of int
        Live states per factor.
    prior : tuple of numpy.ndarray
        ``(sizes[f],)`` float prior per factor, each summing to 1.
    evidence : tuple of tuple of Evidence
        Per time step, the evidence of every modality (and pose) that reported.
    actions : tuple of tuple of int
        ``T - 1`` control tuples, one integer per factor.
    """

    sizes: tuple[int, ...]
    prior: tuple[np.ndarray, ...]
    evidence: tuple[tuple[Evidence, ...], ...]
    actions: tuple[tuple[int, ...], ...]

    @property
    def T(self) -> int:  # noqa: N802 - conventional name
        """Number of time steps."""
        return len(self.evidence)

    @property
    def num_factors(self) -> int:
        """Number of factors."""
        return len(self.sizes)


# -- checking --------------------------------------------------------------------------------
def _check_distribution(x, n_live: int, cap: int, what: str) -> np.ndarray:
    arr = real_array(x, what, InferenceError)  # refuses complex, strings, ragged nesting
    if arr.ndim != 1 or arr.shape[0] not in (n_live, cap):
        raise InferenceError(
            f"{what}: expected a vector of length {n_live} (live) or {cap} (capacity), "
            f"got shape {arr.shape}"
        )
    total = arr.sum()  # not finite when any entry is not; nan fails the comparison below too
    if not (np.isfinite(total) and arr.min() >= 0):
        raise InferenceError(f"{what}: entries must be finite and non-negative")
    if arr.shape[0] > n_live:
        if np.any(arr[n_live:] > 0):
            raise InferenceError(f"{what}: puts mass on entries beyond the {n_live} live ones")
        arr = arr[:n_live]
        total = arr.sum()
    if abs(total - 1.0) > ATOL:
        raise InferenceError(f"{what}: sums to {total:.6g}, expected 1 (normalise it)")
    return arr


def check_prior(model, prior) -> tuple[np.ndarray, ...]:
    F = len(model.factors)
    if isinstance(prior, np.ndarray) and prior.ndim == 1 and F == 1:
        prior = [prior]
    if not isinstance(prior, Sequence) or isinstance(prior, str | bytes):
        raise InferenceError(f"prior: expected a list with one belief per factor ({F})")
    if len(prior) != F:
        raise InferenceError(f"prior: has {len(prior)} entries, the model has {F} factor(s)")
    return tuple(
        _check_distribution(
            p, model.num_states[f], model.state_capacity(f), f"prior for factor '{model.factors[f].name}'"
        )
        for f, p in enumerate(prior)
    )


def _split_step(model, step, t: int) -> tuple[list, object]:
    """Per-modality entries (None when missing) and the metric pose (or None)."""
    M = len(model.modalities)
    has_pose = model.pose is not None
    if isinstance(step, Mapping):
        entries: list = [None] * M
        pose = None
        for key, value in step.items():
            if key == POSE_KEY and POSE_KEY not in model.modality_names:
                if not has_pose:
                    raise InferenceError(f"observations[{t}]: a pose was given but the model has no pose factor")
                pose = value
                continue
            try:
                m = model.modality_index(key)
            except ValueError as err:
                raise InferenceError(f"observations[{t}]: {err}") from None
            entries[m] = value
        return entries, pose
    if isinstance(step, np.ndarray) and step.ndim == 1 and np.issubdtype(step.dtype, np.integer):
        step = list(step)
    if not isinstance(step, Sequence) or isinstance(step, str | bytes):
        if M == 1 and (step is None or isinstance(step, int | np.integer)):
            return [step], None
        raise InferenceError(
            f"observations[{t}]: expected a list with one entry per modality ({M}) or a dict"
        )
    n = len(step)
    if n == M:
        return list(step), None
    if has_pose and n == M + 1:
        return list(step[:M]), step[M]
    extra = " (+1 for the metric pose)" if has_pose else ""
    raise InferenceError(f"observations[{t}]: has {n} entries, the model has {M} modalities{extra}")


def modality_evidence(model, m: int, value, t: int = 0) -> Evidence | None:
    """Likelihood of one modality entry over its factors' live states (None if missing)."""
    if value is None:
        return None
    name = model.modalities[m].name
    n_o = model.num_obs[m]
    deps = model.A_deps[m]
    if isinstance(value, bool | np.bool_):
        raise InferenceError(f"observations[{t}] for modality '{name}': got a bool, expected an index")
    if isinstance(value, int | np.integer):
        o = int(value)
        if not 0 <= o < n_o:
            raise InferenceError(
                f"observations[{t}] for modality '{name}': index {o} out of range "
                f"(live outcomes 0..{n_o - 1})"
            )
        return Evidence(deps, model.A_row(m, o), 0.0, name)
    p = _check_distribution(value, n_o, model.obs_capacity(m), f"observations[{t}] for modality '{name}'")
    return Evidence(deps, model.A[m].expected_row(p[:n_o]), 0.0, name)


def pose_evidence(model, pose, t: int = 0) -> Evidence | None:
    """Gaussian-kernel likelihood of a metric pose over the live states of the pose factor."""
    if pose is None:
        return None
    pm = model.pose
    p = real_array(pose, f"observations[{t}] pose", InferenceError)
    if p.shape != (2,) or not np.all(np.isfinite(p)):
        raise InferenceError(f"observations[{t}] pose: expected finite (x, y), got {pose!r}")
    n = model.num_states[pm.factor]
    diff = pm.poses[:n] - p
    d2 = diff[:, 0] * diff[:, 0] + diff[:, 1] * diff[:, 1]
    logk = d2 * (-0.5 / (pm.sigma * pm.sigma))
    top = float(logk.max())
    return Evidence((pm.factor,), np.exp(logk - top), top, POSE_KEY)


def _controls(a, t: int) -> tuple[int, ...]:
    """One time step's controls as ints; floats, strings and bools are refused, never truncated
    or parsed."""
    if isinstance(a, str | bytes):
        raise InferenceError(f"actions[{t}]: got the string {a!r}, expected integer control indices")
    try:
        arr = np.asarray(a)
    except (TypeError, ValueError):
        raise InferenceError(f"actions[{t}]: expected integer control indices, got {a!r}") from None
    if arr.dtype.kind not in "iu":
        raise InferenceError(f"actions[{t}]: expected integer control indices, got {a!r} ({arr.dtype.name})")
    return tuple(int(x) for x in arr.ravel())


def check_num_iter(num_iter, scheme: str) -> int:
    """``num_iter`` must be an integer >= 1 (zero sweeps would return the prior unchanged)."""
    if isinstance(num_iter, bool | np.bool_) or not isinstance(num_iter, int | np.integer):
        raise InferenceError(f"{scheme}: num_iter must be an integer >= 1, got {num_iter!r}")
    if num_iter < 1:
        raise InferenceError(f"{scheme}: num_iter must be >= 1, got {num_iter}")
    return int(num_iter)


def _check_actions(model, actions, T: int) -> tuple[tuple[int, ...], ...]:
    F = len(model.factors)
    U = model.num_controls
    if actions is None:
        if T > 1 and any(u > 1 for u in U):
            raise InferenceError(f"actions: {T - 1} control tuples are needed for {T} observations")
        return tuple((0,) * F for _ in range(T - 1))
    if isinstance(actions, str | bytes) or not hasattr(actions, "__len__"):
        raise InferenceError("actions: expected a sequence of per-factor control tuples")
    if len(actions) != T - 1:
        raise InferenceError(f"actions: has {len(actions)} entries, expected T - 1 = {T - 1}")
    out = []
    for t, a in enumerate(actions):
        if isinstance(a, int | np.integer):
            a = (a,)
        a = _controls(a, t)
        if len(a) != F:
            raise InferenceError(f"actions[{t}]: has {len(a)} controls, the model has {F} factor(s)")
        for f, u in enumerate(a):
            if not 0 <= u < U[f]:
                raise InferenceError(
                    f"actions[{t}]: control {u} out of range for factor "
                    f"'{model.factors[f].name}' ({U[f]} controls)"
                )
        out.append(a)
    return tuple(out)


def prepare(model, prior, observations, actions=None) -> Problem:
    """Check a scheme's inputs and turn observations into :class:`Evidence` on live slices.

    User-written schemes can call this to get the same checks and conventions as ours.

    Parameters
    ----------
    model : Model
        Compiled model (:func:`cogmap.genmodel.compile`).
    prior : list of numpy.ndarray
        One belief per factor at the first step, before its observation: ``(num_states[f],)`` float
        (or capacity length with no mass beyond the live states), sums to 1.
    observations : sequence
        ``T >= 1`` steps; each a list with one entry per modality (plus the metric pose ``(x, y)``
        in metres when the model has a pose factor) or a dict keyed by modality name (and
        ``"pose"``). An entry is an outcome index, a distribution over the live outcomes, or None
        (missing). See :mod:`cogmap.inference.base`.
    actions : sequence, optional
        ``T - 1`` control tuples, one integer per factor (a bare int for one factor); may be omitted
        when every factor has a single control.

    Returns
    -------
    Problem

    Raises
    ------
    InferenceError
        Naming the argument and the problem (wrong lengths, unnormalised or negative beliefs,
        outcome indices out of range, bad controls, a pose without a pose factor).
    """
    priors = check_prior(model, prior)
    if isinstance(observations, str | bytes) or not hasattr(observations, "__len__"):
        raise InferenceError("observations: expected a sequence over time (length T >= 1)")
    T = len(observations)
    if T < 1:
        raise InferenceError("observations: empty sequence (need T >= 1)")
    evidence = []
    for t, step in enumerate(observations):
        entries, pose = _split_step(model, step, t)
        ev = [modality_evidence(model, m, v, t) for m, v in enumerate(entries)]
        ev.append(pose_evidence(model, pose, t))
        evidence.append(tuple(e for e in ev if e is not None))
    return Problem(
        tuple(model.num_states), priors, tuple(evidence), _check_actions(model, actions, T)
    )


def check_possible(model, prob: Problem, scheme: str) -> None:
    """Refuse observations that have probability 0 under the model, as exact Bayes does.

    Variational schemes work with floored logarithms and would otherwise return a posterior for
    an impossible observation. This follows which states are possible (the support of the prior,
    pushed through ``B`` under each step's controls) and, at each step, keeps the states every
    reporting modality gives a positive likelihood; the metric pose (a Gaussian) rules nothing
    out. With one factor the test is exact; with several, each modality is checked against the
    possible states of its factors (arc consistency), so every refusal is right but an
    observation that only the joint of several modalities rules out can pass (use ``exact``).

    Parameters
    ----------
    model : Model
        Compiled model.
    prob : Problem
        The checked inputs (:func:`prepare`).
    scheme : str
        Name of the scheme, for the message.

    Raises
    ------
    InferenceError
        ``"<scheme>: observations up to step <t> have zero probability under the model"``, the
        message of ``exact`` and ``filter``.
    """
    possible = [p > 0 for p in prob.prior]
    for t in range(prob.T):
        if t > 0:
            # a factor that depends on several is possible where some possible state of each
            # dependency leads to it (the mean-field prediction of the masks is positive there)
            possible = [p > 0 for p in predict_factorised(model, [s.astype(float) for s in possible],
                                                          prob.actions[t - 1])]
        for ev in prob.evidence[t]:
            if ev.name == POSE_KEY:
                continue
            mask = ev.lik > 0
            for axis, f in enumerate(ev.deps):
                shape = [1] * mask.ndim
                shape[axis] = -1
                mask = mask & possible[f].reshape(shape)
            for axis, f in enumerate(ev.deps):
                possible[f] = mask.any(axis=tuple(a for a in range(mask.ndim) if a != axis))
            if not mask.any():
                break
        if not all(p.any() for p in possible):
            raise InferenceError(f"{scheme}: observations up to step {t} have zero probability under the model")


# -- small maths -----------------------------------------------------------------------------
# floor_log, softmax, xlogx_sum and LOG_FLOOR: cogmap.genmodel.numerics (imported above)


def dense_transition(model, f: int, u: int) -> np.ndarray:
    """Live dense ``B[f][:, :, u]`` (``(next, current)``), whatever the storage.

    Raises
    ------
    InferenceError
        If the factor's next state depends on other factors too (there is no ``(next, current)``
        matrix; see :func:`predict_factorised`).
    """
    deps = getattr(model, "B_deps", None)
    if deps is not None and deps[f] != (f,):
        names = [model.factors[d].name for d in deps[f]]
        raise InferenceError(f"factor '{model.factors[f].name}': its transitions depend on the factors {names} "
                             "(B_dependencies); this computation needs transitions that depend on the factor "
                             "alone")
    return model.B[f].control_dense(u, model.num_states[f])


def transition_array(model, f: int, u: int) -> np.ndarray:
    """Live ``B[f][..., u]``: ``(next, current)`` (:func:`dense_transition`), or ``(next, *deps)``
    for a factor whose next state depends on several factors (``model.B_deps[f]``)."""
    deps = getattr(model, "B_deps", None)
    if deps is not None and deps[f] != (f,):
        return model.B[f].prob[..., u]
    return dense_transition(model, f, u)


def b_deps_of(model) -> tuple[tuple[int, ...], ...]:
    """Per factor, the factors its next state depends on (``(f,)`` alone without ``B_deps``)."""
    deps = getattr(model, "B_deps", None)
    return tuple((f,) for f in range(len(model.B))) if deps is None else deps


def forward_message(b: np.ndarray, deps_f: tuple[int, ...], f: int, q_prev) -> np.ndarray:
    """``b`` (``B`` or ``log B`` of factor ``f``, as :func:`transition_array`) contracted with the
    beliefs ``q_prev[d]`` of its dependencies at the previous step: a function of ``s_t^f``."""
    if deps_f == (f,):
        return b @ q_prev[f]
    return marginal_loglik(b, tuple(range(len(deps_f) + 1)), [None] + [q_prev[d] for d in deps_f], 0)


def backward_message(log_b: np.ndarray, deps_g: tuple[int, ...], g: int, f: int, q_next_g, q_now) -> np.ndarray:
    """``E[log B_g(s_t+1^g | s_t^deps_g)]`` as a function of ``s_t^f`` (``f`` in ``deps_g``), under
    ``q_next_g`` and the beliefs ``q_now[d]`` at ``t`` of ``g``'s other dependencies."""
    if deps_g == (g,):
        return q_next_g @ log_b
    local = [q_next_g] + [q_now[d] for d in deps_g]
    return marginal_loglik(log_b, tuple(range(len(deps_g) + 1)), local, 1 + deps_g.index(f))


def refuse_B_deps(model, scheme: str) -> None:
    """Refuse a model in which some factor's next state depends on other factors' previous states.

    Parameters
    ----------
    model : Model
        Compiled model.
    scheme : str
        Name of the scheme (or other feature) without support, for the message.

    Raises
    ------
    InferenceError
        Naming ``scheme`` and the factors with dependencies (pymdp's ``B_dependencies``).
    """
    refuse = getattr(model, "refuse_B_deps", None)
    if refuse is not None:
        refuse(f"{scheme}", InferenceError)


def predict_dependent(B, qs, u: int) -> np.ndarray:
    """Mean-field prediction ``sum_{s_deps} B[:, s_deps, u] prod_d q_d(s_d)`` of one factor whose
    transitions depend on several factors (pymdp 1.0's ``compute_expected_state``).

    Parameters
    ----------
    B : DependentTransitions
        The factor's transitions (:class:`cogmap.genmodel.transitions.DependentTransitions`).
    qs : sequence of numpy.ndarray
        ``(n_g,)`` float belief of every factor ``g`` (those in ``B.deps`` are used).
    u : int
        The factor's control.

    Returns
    -------
    numpy.ndarray
        ``(n_f,)`` float predicted belief.
    """
    return B.predict_from([np.asarray(qs[d], dtype=float) for d in B.deps], u)


def marginal_loglik(loglik: np.ndarray, deps: tuple[int, ...], qs, f: int) -> np.ndarray:
    """``E_{q(other deps)}[loglik]`` as a function of factor ``f`` (which must be in ``deps``)."""
    x = loglik
    keep = deps.index(f)
    # the axes after f's as matrix-vector products on the last axis, then those before it on the first
    for axis in range(len(deps) - 1, keep, -1):
        x = x @ qs[deps[axis]]
    for axis in range(keep):
        x = (qs[deps[axis]] @ x.reshape(x.shape[0], -1)).reshape(x.shape[1:])
    return x


def expected_loglik(loglik: np.ndarray, deps: tuple[int, ...], qs) -> float:
    x = loglik
    for axis in range(len(deps) - 1, -1, -1):  # contract the last axis, from the last factor back
        x = x @ qs[deps[axis]]
    return float(x)


def predict_factorised(model, qs, action) -> list[np.ndarray]:
    """Per-factor one-step prediction ``B[f][:, :, u_f] q_f`` (dense or sparse storage).

    A factor whose next state depends on several factors (``model.B_deps[f] != (f,)``) is
    predicted by contracting its ``B`` with the product of its dependencies' beliefs
    (mean field, as pymdp 1.0's ``compute_expected_state``): the marginal of the exact joint
    prediction from the product prior ``prod_f q_f``.

    Parameters
    ----------
    model : Model
        Compiled model.
    qs : sequence of numpy.ndarray
        ``(n_f,)`` float belief per factor.
    action : sequence of int
        One control per factor.

    Returns
    -------
    list of numpy.ndarray
        ``(n_f,)`` float predicted belief per factor.
    """
    deps = getattr(model, "B_deps", None)
    if deps is None or all(d == (f,) for f, d in enumerate(deps)):
        return [model.predict(f, q, int(u)) for f, (q, u) in enumerate(zip(qs, action, strict=True))]
    return [model.predict(f, q, int(u)) if deps[f] == (f,) else predict_dependent(model.B[f], qs, int(u))
            for f, (q, u) in enumerate(zip(qs, action, strict=True))]

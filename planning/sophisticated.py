"""Sophisticated inference: expected free energy recursed over actions *and* the outcomes they bring.

Enumeration (:mod:`~.policies`) and MCTS (:mod:`~.mcts`) roll beliefs forward without looking at
what the agent will observe on the way. Sophisticated inference (Friston et al. 2021, *Sophisticated
inference*, Neural Computation 33(3); SPM's ``spm_forwards`` in ``spm_MDP_VB_XX.m`` and
``spm_MDP_VB_XXX.m``) plans over beliefs that are updated on every imagined outcome, so a plan may
depend on what it will see: read the cue, *then* go where it points. With belief ``q_t`` and ``d``
steps to go, the expected free energy of the joint control ``u`` is ::

    G(q_t, u) = G_1(q_t, u)
                + sum_o P(o | q_t, u) sum_u' q(u' | q_{t+1}^{o,u}) G(q_{t+1}^{o,u}, u')   (d > 1)

``G_1`` is the objective's one-step value (:class:`~.efe.Objective` on a step context of every joint
control, lower is better), ``q_{t+1}^{o,u}`` the exact Bayesian posterior over the *joint* hidden
state (all factors: predict every factor through ``B`` under ``u``, then condition on the joint
outcome ``o`` of all modalities), and ``q(u' | q) = softmax(-gamma G(q, u'))`` over the next joint
controls, with ``G(q, u')`` the recursive value itself. Beliefs are exact joints at every node; the
objective's terms that read per-factor beliefs (state preferences, ``B`` novelty, the inductive
term) see the joint's marginals, those that read outcomes (utility, state information gain,
ambiguity, ``A`` novelty) the exact joint over each modality's factors. Model parameters (and so
novelty) are not updated along imagined branches, as in SPM.

Pruning (:class:`SophisticatedConfig`), as SPM's ``spm_forwards`` does it at every node, the root
included:

* **actions**: a control is expanded only if its one-step probability ``softmax(-gamma G_1)`` is
  at least ``action_threshold`` (1/16) times the largest one (``u > max(u)/16`` in
  ``spm_forwards``, strictly; here ``>=`` so that a threshold of 0 expands everything; the most
  probable control is always expanded). A pruned control gets the value
  ``min(G) + 512 / gamma`` (``G`` of the expanded controls, after their recursion): a
  probability ``e^-512`` times the best one's. It still takes part, at that value, in the softmax
  that weighs a node's controls (as in ``spm_forwards``), where its weight is negligible;
* **outcomes**: under an expanded control, a joint outcome is expanded only if its predicted
  probability is at least ``outcome_threshold`` (1/16), at most the ``max_outcomes`` (16) most
  probable ones and always at least the most probable one. Joint outcomes are built modality by
  modality from the partial outcomes above threshold (a joint outcome is never more probable than
  any of its parts, so nothing above threshold is lost unless more than ``max_outcomes`` partial
  outcomes pass); cost and memory per node are bounded by ``max_outcomes`` whatever the number of
  modalities. The weights of the expanded outcomes are renormalised to sum to 1, as
  ``spm_MDP_VB_XXX``'s ``spm_forwards`` renormalises its plausible combinations
  (``spm_MDP_VB_XX`` does not).

Where this differs from SPM:

* SPM branches on plausible *hidden states* ``s`` and conditions on their likelihood ``A(:, s)``
  as soft evidence; here the branches are the plausible joint *outcomes* and each posterior is the
  exact Bayes posterior given that outcome (the recursion as written in Friston et al. 2021);
* SPM's tree weighs controls with unit precision; here with ``gamma`` (the loop's policy
  precision), and the root's ``q(u) = softmax(-gamma G)`` is the policy posterior of the ``Plan``;
* ``spm_MDP_VB_XXX`` updates factorised (mean-field) beliefs with ``spm_VBX``; here beliefs are the
  exact joint over all factors (as the Kronecker form of ``spm_MDP_VB_XX``);
* the thresholds are on probabilities of outcomes rather than of states (``spm_MDP_VB_XX``: states
  above ``max/16``, at most 16; ``spm_MDP_VB_XXX``: states above ``exp(-8)`` per factor, the 4 most
  likely combinations), and the pruned controls' value is set after the recursion, relative to the
  best expanded one, so that a pruned control can never outrank an expanded one;
* the horizon counts the steps evaluated: ``horizon = 1`` is the one-step EFE (SPM's ``N = 0``);
* no prior over controls (SPM's ``E``) and no covert (attentional) policies.

Identical posteriors reached by different paths at the same depth are evaluated once.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from cogmap.genmodel.numerics import softmax

from .action_selection import select_action
from .arrays import Prepared, as_arrays, prepare
from .context import DenseStep
from .policies import enumerate_policies
from .threads import limited

PRUNED_LOG_WEIGHT = 512.0  # a pruned control is this many nats (of -gamma G) below the best expanded one


@dataclass(frozen=True)
class SophisticatedConfig:
    """Pruning and size limits of the sophisticated search (see the module docstring).

    Attributes
    ----------
    outcome_threshold : float
        Predicted probability, in [0, 1], below which a joint outcome is not expanded (SPM: 1/16);
        0 expands every outcome of nonzero probability.
    action_threshold : float
        Fraction, in [0, 1], of the most probable control's one-step probability below which a
        control is not expanded (SPM: 1/16); 0 expands every control.
    max_outcomes : int or None
        Most joint outcomes expanded under a control (and partial outcomes kept per modality),
        default 16; None: no limit (exhaustive search on small models).
    max_states : int
        Largest joint state space (product of the factors' live states) planned with, default 4096.
    """

    outcome_threshold: float = 1.0 / 16.0
    action_threshold: float = 1.0 / 16.0
    max_outcomes: int | None = 16
    max_states: int = 4096


#: thresholds 0 and no outcome limit: the exhaustive recursion (small models only)
EXHAUSTIVE = SophisticatedConfig(outcome_threshold=0.0, action_threshold=0.0, max_outcomes=None)


class SophisticatedInfo(NamedTuple):
    """What the search did for one decision (``Plan.info`` of the ``"sophisticated"`` planner).

    Attributes
    ----------
    G_one_step : numpy.ndarray
        ``(U,)`` float one-step EFE of every root control.
    expanded : numpy.ndarray
        ``(U,)`` bool, the root controls that were expanded (always all at ``horizon`` 1).
    nodes : int
        Beliefs evaluated (step contexts of all ``U`` controls).
    reused : int
        Beliefs met again at the same depth and not evaluated again.
    """

    G_one_step: np.ndarray
    expanded: np.ndarray
    nodes: int
    reused: int


def _check(horizon, gamma, config: SophisticatedConfig) -> None:
    if isinstance(horizon, bool) or not isinstance(horizon, int | np.integer) or horizon < 1:
        raise ValueError(f"sophisticated: horizon (policy_len) must be an integer >= 1, got {horizon!r}")
    if isinstance(gamma, bool) or not isinstance(gamma, int | float | np.integer | np.floating) \
            or not np.isfinite(gamma) or gamma <= 0:
        raise ValueError(f"sophisticated: gamma must be a finite positive number, got {gamma!r}")
    for name in ("outcome_threshold", "action_threshold"):
        v = getattr(config, name)
        if isinstance(v, bool) or not isinstance(v, int | float | np.integer | np.floating) \
                or not np.isfinite(v) or not 0.0 <= v <= 1.0:
            raise ValueError(f"sophisticated: {name} must be a probability in [0, 1], got {v!r}")
    mo = config.max_outcomes
    if mo is not None and (isinstance(mo, bool) or not isinstance(mo, int | np.integer) or mo < 1):
        raise ValueError(f"sophisticated: max_outcomes must be an integer >= 1 or None, got {mo!r}")
    ms = config.max_states
    if isinstance(ms, bool) or not isinstance(ms, int | np.integer) or ms < 1:
        raise ValueError(f"sophisticated: max_states must be an integer >= 1, got {ms!r}")


def _marginal(x: np.ndarray, shape: tuple, deps: Sequence[int]) -> np.ndarray:
    """``(c, prod n_deps)`` marginal of batched joints ``x`` (``(c, prod shape)``) over the factors
    ``deps``, their axes in the order of ``deps`` (the order of a likelihood's state axes)."""
    deps = tuple(deps)
    c = x.shape[0]
    if deps == tuple(range(len(shape))):
        return x
    X = x.reshape(c, *shape)
    others = tuple(1 + f for f in range(len(shape)) if f not in deps)
    if others:
        X = X.sum(axis=others)
    order = sorted(deps)
    if list(deps) != order:
        X = X.transpose(0, *(1 + order.index(f) for f in deps))
    return X.reshape(c, -1)


class _JointStep(DenseStep):
    """A :class:`~.context.DenseStep` whose belief is an exact joint over the factors (not a product).

    ``qs`` / ``qs_prev`` are the joint's marginals; expectations over a modality's factors
    (outcomes, ambiguity, ``A`` novelty) use the joint's marginal over those factors.
    """

    def __init__(self, prep: Prepared, prior: np.ndarray, predicted: np.ndarray, actions: np.ndarray,
                 shape: tuple, t: int):
        self.prep = prep
        self._a = prep.arrays
        self.actions = actions
        self.t = t
        self.collision = None
        self._joint = predicted  # (K, N)
        self._shape = shape
        K = predicted.shape[0]
        F = len(shape)
        self.qs = [_marginal(predicted, shape, (f,)) for f in range(F)]
        self.qs_prev = [np.broadcast_to(_marginal(prior[None], shape, (f,))[0], (K, shape[f])) for f in range(F)]
        self._marginals = {}

    def _expect(self, T, deps, keep_first):
        deps = tuple(deps)
        m = self._marginals.get(deps)
        if m is None:
            m = self._marginals[deps] = _marginal(self._joint, self._shape, deps)
        size = m.shape[1]
        return m @ (T.reshape(-1, size).T if keep_first else T.reshape(size))


class _Search:
    """The recursion of one decision: the model's arrays, the controls and the caches."""

    def __init__(self, prep: Prepared, objective, gamma: float, config: SophisticatedConfig):
        a = prep.arrays
        self.prep, self.objective, self.gamma, self.config = prep, objective, float(gamma), config
        self.shape = tuple(int(n) for n in a.num_states)
        self.F = len(self.shape)
        self.actions = enumerate_policies(a.num_controls, 1)[:, 0, :]  # (U, F), the enumerate order
        # per factor, B as (n, n * u): M[s, s' * u + c] = B[s', s, c] (one product predicts every control)
        self.M = [np.ascontiguousarray(np.asarray(b, dtype=float).transpose(1, 0, 2)).reshape(b.shape[1], -1)
                  for b in prep.B]
        self.num_controls = tuple(int(b.shape[2]) for b in prep.B)
        # per modality: A as (o, prod n_deps) for outcome probabilities and as (o, *broadcast shape)
        # over the joint for the Bayes update
        self.A2d, self.Ajoint, self.deps = [], [], []
        for m in range(len(a.A)):
            deps = tuple(a.A_deps[m])
            A_m = np.asarray(a.live_A(m), dtype=float)
            self.deps.append(deps)
            self.A2d.append(np.ascontiguousarray(A_m.reshape(A_m.shape[0], -1)))
            order = sorted(deps)
            A_sorted = A_m.transpose(0, *(1 + deps.index(f) for f in order))
            bshape = tuple(self.shape[f] if f in deps else 1 for f in range(self.F))
            self.Ajoint.append(np.ascontiguousarray(A_sorted).reshape(A_m.shape[0], *bshape))
        self.memo: dict = {}
        self.nodes = 0
        self.reused = 0

    def predict(self, belief: np.ndarray) -> np.ndarray:
        """``(U, N)`` predicted joints under every joint control (the last factor's control fastest)."""
        X = belief.reshape(1, *self.shape)
        for f, M in enumerate(self.M):
            n, u = self.shape[f], self.num_controls[f]
            Xf = np.moveaxis(X, 1 + f, -1)  # (c, other factors..., n_f)
            Y = (Xf.reshape(-1, n) @ M).reshape(*Xf.shape[:-1], n, u)  # (c, others..., s'_f, u)
            Y = np.moveaxis(np.moveaxis(Y, -1, 1), -1, 2 + f)  # (c, u, n_1, ..., n_F)
            X = Y.reshape(-1, *self.shape)
        return X.reshape(X.shape[0], -1)

    def branches(self, predicted: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Renormalised weights ``(J,)`` and posteriors ``(J, N)`` of the expanded joint outcomes."""
        thr, cap = self.config.outcome_threshold, self.config.max_outcomes
        W = predicted[None]  # (c, N): unnormalised joint of the state and the partial outcome
        for m, deps in enumerate(self.deps):
            A2 = self.A2d[m]
            P = (_marginal(W, self.shape, deps) @ A2.T).ravel()  # (c * o_m,) partial outcome probabilities
            pick = np.flatnonzero((P > 0.0) & (P >= thr))
            if pick.size == 0:
                pick = np.array([int(np.argmax(P))])
            if cap is not None and pick.size > cap:
                pick = pick[np.argsort(-P[pick], kind="stable")[:cap]]
            ci, oi = np.divmod(pick, A2.shape[0])
            W = (W[ci].reshape(-1, *self.shape) * self.Ajoint[m][oi]).reshape(pick.size, -1)
        p = W.sum(axis=1)
        return p / p.sum(), W / p[:, None]

    def node(self, belief: np.ndarray, depth: int, t: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(G, G_one_step, expanded)`` of every joint control from ``belief`` with ``depth`` steps to go."""
        key = (depth, belief.tobytes())
        hit = self.memo.get(key)
        if hit is not None:
            self.reused += 1
            return hit
        self.nodes += 1
        predicted = self.predict(belief)
        ctx = _JointStep(self.prep, belief, predicted, self.actions, self.shape, t)
        G1 = np.asarray(self.objective(ctx), dtype=float).reshape(-1)
        if G1.shape != (len(self.actions),):
            raise ValueError(f"sophisticated: the objective returned shape {G1.shape} for "
                             f"{len(self.actions)} candidates")
        if depth == 1:
            out = (G1, G1, np.ones(G1.shape, dtype=bool))
        else:
            q = softmax(-self.gamma * G1)
            expanded = q >= self.config.action_threshold * q.max()
            G = G1.copy()
            for k in np.flatnonzero(expanded):
                weights, posteriors = self.branches(predicted[k])
                future = 0.0
                for w, post in zip(weights, posteriors, strict=True):
                    Gc = self.node(post, depth - 1, t + 1)[0]
                    future += w * float(softmax(-self.gamma * Gc) @ Gc)
                G[k] += future
            if not expanded.all():
                G[~expanded] = G[expanded].min() + PRUNED_LOG_WEIGHT / self.gamma
            out = (G, G1, expanded)
        self.memo[key] = out
        return out


def _prepared(model, config: SophisticatedConfig) -> Prepared:
    if isinstance(model, Prepared):
        if model.local:
            raise ValueError("sophisticated: needs a dense preparation (prepare(..., local=False)); "
                             "the local (sparse-path) one plans a single sparse factor only")
        a = model.arrays
    else:
        a = as_arrays(model)
    if getattr(a, "has_B_deps", False):
        raise ValueError("sophisticated: transitions that depend on several factors (B_dependencies) are not "
                         "supported; use the 'enumerate' planner for such models")
    size = int(np.prod([int(n) for n in a.num_states], dtype=np.int64))
    if size > config.max_states:
        sparse = [f for f in range(a.num_factors) if a.is_sparse(f)]
        kind = f"sparse factor(s) {sparse}: densified, " if sparse else ""
        raise ValueError(f"sophisticated: the joint state space has {size} states ({kind}limit "
                         f"max_states={config.max_states}); plan this model with 'mcts' or 'enumerate'")
    if size == 0:
        raise ValueError("sophisticated: the model has no live states")
    return model if isinstance(model, Prepared) else prepare(a, local=False)


def sophisticated_efe(model, qs: Sequence[np.ndarray], objective=None, horizon: int = 1, gamma: float = 16.0,
                  config: SophisticatedConfig | None = None) -> tuple[np.ndarray, SophisticatedInfo]:
    """Expected free energy of every joint control, recursed over actions and outcomes.

    Parameters
    ----------
    model : Model or PlanningArrays or Prepared
        The model (dense; sparse transitions or likelihoods are densified, up to
        ``config.max_states`` joint states; a local preparation is refused).
    qs : sequence of numpy.ndarray
        Current belief per factor, ``(n_f,)`` (or capacity length; trimmed to live states).
    objective : Objective, optional
        Per-step EFE; default :func:`~.efe.pymdp_like` (utility + state information gain).
    horizon : int, optional
        Steps evaluated, >= 1 (1: the one-step EFE), default 1.
    gamma : float, optional
        Precision of ``q(u) = softmax(-gamma G)`` at every node, default 16.
    config : SophisticatedConfig, optional
        Pruning thresholds and limits (default: SPM's, see the module docstring).

    Returns
    -------
    G : numpy.ndarray
        ``(U,)`` float, one per joint control in the order of
        ``enumerate_policies(num_controls, 1)`` (lower is better).
    info : SophisticatedInfo
        One-step values, expanded root controls and the size of the search.

    Raises
    ------
    ValueError
        ``horizon`` < 1, a non-positive ``gamma``, thresholds outside [0, 1], a bad
        ``max_outcomes`` / ``max_states``, a local preparation or too many joint states.
    """
    config = SophisticatedConfig() if config is None else config
    _check(horizon, gamma, config)
    if objective is None:
        from .efe import pymdp_like

        objective = pymdp_like()
    prep = _prepared(model, config)
    a = prep.arrays
    if len(qs) != a.num_factors:
        raise ValueError(f"sophisticated: got beliefs for {len(qs)} factor(s), the model has {a.num_factors}")
    belief = np.ones(())
    for f, q in enumerate(qs):
        belief = np.multiply.outer(belief, np.asarray(q, dtype=float)[: a.num_states[f]])
    with limited():
        search = _Search(prep, objective, gamma, config)
        G, G1, expanded = search.node(belief.reshape(-1), int(horizon), 0)
    return G.copy(), SophisticatedInfo(G1.copy(), expanded.copy(), search.nodes, search.reused)


def sophisticated_planner(model, qs, objective, settings, config: SophisticatedConfig | None = None):
    """The ``"sophisticated"`` planner: :func:`sophisticated_efe` with ``horizon = settings.policy_len``.

    Parameters
    ----------
    model, qs, objective
        As for :func:`sophisticated_efe` (``objective`` None: pymdp's default).
    settings : PlanSettings
        ``policy_len`` (the horizon), ``gamma``, ``sample``, ``rng``, ``alpha`` and ``sampling``
        (``log_E`` weighs enumerated policies and is not used).
    config : SophisticatedConfig, optional
        Pruning thresholds and limits.

    Returns
    -------
    Plan
        The chosen control per factor (:func:`~.action_selection.select_action`), ``G`` and
        ``q_pi = softmax(-gamma G)`` per root joint control, ``policies`` ``(U, 1, F)`` (those
        controls) and ``info`` (:class:`SophisticatedInfo`).
    """
    from .plan import Plan
    from .policies import policy_posterior

    G, info = sophisticated_efe(model, qs, objective, settings.policy_len, settings.gamma, config)
    a = model.arrays if isinstance(model, Prepared) else as_arrays(model)
    policies = enumerate_policies(a.num_controls, 1)
    q_pi = policy_posterior(G, settings.gamma)
    rng = settings.rng if settings.sample else None
    action = select_action(q_pi, policies, a.num_controls, settings.alpha, settings.sampling, rng)
    return Plan(tuple(int(x) for x in action), G, q_pi, policies, info)


def planner_with(config: SophisticatedConfig):
    """A planner like ``"sophisticated"`` with other thresholds, to register under a name of yours:
    ``register_planner("si_exhaustive", planner_with(EXHAUSTIVE))``.

    Parameters
    ----------
    config : SophisticatedConfig
        Pruning thresholds and limits.

    Returns
    -------
    callable
        ``planner(model, qs, objective, settings) -> Plan``.
    """
    _check(1, 1.0, config)

    def planner(model, qs, objective, settings):
        return sophisticated_planner(model, qs, objective, settings, config)

    return planner


__all__ = ["EXHAUSTIVE", "SophisticatedConfig", "SophisticatedInfo", "planner_with", "sophisticated_efe",
           "sophisticated_planner"]

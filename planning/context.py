"""Step contexts: what an EFE term sees for one planning step of ``K`` candidates.

Both contexts expose the same attributes, computed lazily so an objective only pays for the
terms it uses:

``num_candidates``, ``actions`` (K, F), ``t``, ``qs`` (per factor, (K, n_f): predicted states),
``qs_prev``, ``qo`` (per modality, (K, o_m)), ``ambiguity`` (per modality, (K,)),
``a_novelty`` / ``b_novelty`` (per modality / factor, (K,) or None), ``C``, ``C_states``,
``poses``, ``pose_factor``, ``pose_sigma``, ``target_pose``, ``collision`` ((K,) or None),
``collision_pref``, ``closer`` ((K,) or None), ``view`` ((K,) or None: expected unseen
fraction of the predicted state's view).

:class:`DenseStep` works on full (multi-factor) beliefs, like pymdp. :class:`LocalStep` works on
one factor with sparse transitions from a sparse prior: every array is restricted to ``U``, the
states the candidates can reach, so its cost is independent of the size of the map.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from . import inductive as ind
from .arrays import Prepared
from .efe import entropy, xlogx

_LETTERS = "abcdefghijklmnopqrstuvwxyz"
_JOINT_LIMIT = 1 << 16  # entries of the (K, prod d_i) joint below which expect forms it outright


class cached_property:  # noqa: N801 - a lock-free variant of functools.cached_property
    """Computed on first access, then stored on the instance (no lock: contexts are local)."""

    def __init__(self, func):
        self.func = func
        self.name = func.__name__
        self.__doc__ = func.__doc__

    def __get__(self, obj, cls=None):
        if obj is None:
            return self
        value = self.func(obj)
        obj.__dict__[self.name] = value
        return value


@lru_cache(maxsize=64)
def _subscripts(ndeps: int, keep_first: bool) -> str:
    dims = _LETTERS[:ndeps]
    lhs = ("o" if keep_first else "") + dims
    ins = ",".join("K" + d for d in dims)
    return f"{lhs},{ins}->K" + ("o" if keep_first else "")


def joint(qs: list[np.ndarray]) -> np.ndarray | None:
    """``(K, d_1 * ... * d_n)`` joint of batched factor beliefs ``qs[i]`` ((K, d_i)), flattened;
    None when it would exceed ``_JOINT_LIMIT`` entries."""
    K = qs[0].shape[0]
    size = 1
    for q in qs:
        size *= q.shape[1]
    if K * size > _JOINT_LIMIT:
        return None
    out = qs[0]
    for q in qs[1:]:
        out = (out[:, :, None] * q[:, None, :]).reshape(K, -1)
    return out


def expect(T: np.ndarray, qs: list[np.ndarray], keep_first: bool = False, joint_qs=None) -> np.ndarray:
    """Contract tensor ``T`` ((o,)? x d_1 x ... x d_n) with batched factor beliefs ``qs[i]``
    of shape (K, d_i); returns (K, o) when ``keep_first`` else (K,). ``joint_qs``: their
    :func:`joint`, when already formed."""
    if len(qs) == 1:
        return qs[0] @ (T.T if keep_first else T)
    j = joint(qs) if joint_qs is None else joint_qs
    if j is None:  # the joint over the factors would be large: contract one factor at a time
        return np.einsum(_subscripts(len(qs), keep_first), T, *qs, optimize=True)
    size = j.shape[1]
    return j @ (T.reshape(-1, size).T if keep_first else T.reshape(size))


def _predict(B: np.ndarray, q: np.ndarray, u: np.ndarray) -> np.ndarray:
    """``(K, n)`` beliefs ``B[:, :, u_k] q_k`` of ``K`` candidates from ``(K, n)`` beliefs ``q``."""
    K, n = q.shape
    if K * n * n <= _JOINT_LIMIT:  # small: one batched product over the candidates' matrices
        return np.matmul(np.moveaxis(B[:, :, u], 2, 0), q[:, :, None])[:, :, 0]
    out = np.empty_like(q)
    for c in np.unique(u):  # large: one product per distinct control
        rows = u == c
        out[rows] = q[rows] @ B[:, :, c].T
    return out


def _predict_dependent(B: np.ndarray, qs_deps: list, u: np.ndarray) -> np.ndarray:
    """``(K, n_f)`` mean-field predictions ``sum_{s_deps} B[:, s_deps, u_k] prod_d q_dk(s_d)`` of a
    factor whose ``B`` ``(n_f, *n_deps, u)`` depends on several factors, from the candidates'
    ``(K, n_d)`` beliefs of its dependencies (pymdp 1.0's ``compute_expected_state``)."""
    out = np.empty((u.shape[0], B.shape[0]))
    for c in np.unique(u):
        rows = u == c
        out[rows] = expect(B[..., c], [q[rows] for q in qs_deps], keep_first=True)
    return out


class _Common:
    prep: Prepared
    collision: np.ndarray | None

    @property
    def num_candidates(self) -> int:
        """Number of candidates ``K`` evaluated in this step."""
        return self.actions.shape[0]

    @property
    def C(self) -> list:
        """Per modality, the ``(num_obs[m],)`` float log-preferences over live outcomes."""
        a = self.prep.arrays
        return [a.C[m][: a.num_obs[m]] for m in range(len(a.A))]

    @property
    def pose_factor(self) -> int:
        """Index of the factor carrying poses."""
        return self.prep.arrays.pose_factor

    @property
    def pose_sigma(self) -> float:
        """Width (metres) of the position preference."""
        return self.prep.arrays.pose_sigma

    @property
    def target_pose(self):
        """``(2,)`` float target position (metres) of the position preference, or None."""
        return self.prep.arrays.target_pose

    @property
    def collision_pref(self) -> float:
        """Log-preference of a collision (no collision: 0)."""
        return self.prep.arrays.collision_pref

    def _expect(self, T, deps, keep_first):
        """``T`` contracted with the predicted beliefs of the factors ``deps`` (:func:`expect`)."""
        qs = [self.qs[f] for f in deps]
        if len(deps) == 1:
            return expect(T, qs, keep_first)
        joints = self.__dict__.setdefault("_joints", {})  # modalities that share factors share the joint
        if deps not in joints:
            joints[deps] = joint(qs)
        return expect(T, qs, keep_first, joints[deps])

    @cached_property
    def closer(self):
        """``(K,)`` float probability of moving strictly closer to a goal state, or None without a goal.

        Staying on a goal state counts too; only goals within the inductive horizon count (Eq. 9 of the
        AIMAPP paper).
        """
        dist = self.prep.dist
        if dist is None:
            return None
        q, to_goal, from_anchor = self._goal_distances(dist)
        return ind.closer_probability(q, to_goal, from_anchor, self.prep.arrays.inductive_depth)


class DenseStep(_Common):
    """One planning step from batched beliefs ``qs_prev`` under ``actions``, on full (multi-factor) beliefs.

    Predicted beliefs ``qs`` are computed on construction; the other attributes listed in the module
    docstring are computed on first access.

    Parameters
    ----------
    prep : Prepared
        Derived arrays of the decision (dense path).
    qs_prev : list of numpy.ndarray
        Per factor, ``(K, n_f)`` float beliefs before the step, rows sum to 1.
    actions : numpy.ndarray
        ``(K, F)`` int, one control per factor for each candidate.
    t : int, optional
        Index of the step within the imagined policy, default 0.
    collision : numpy.ndarray or None, optional
        ``(K,)`` float probability of a collision per candidate (first step only), or None.
    """

    def __init__(self, prep: Prepared, qs_prev: list, actions: np.ndarray, t: int = 0, collision=None):
        self.prep = prep
        self.actions = np.asarray(actions)
        self.t = t
        self.qs_prev = qs_prev
        self.collision = collision
        a = prep.arrays
        deps = a.B_deps
        self.qs = [_predict(prep.B[f], q, self.actions[:, f]) if deps[f] == (f,) else
                   _predict_dependent(prep.B[f], [qs_prev[d] for d in deps[f]], self.actions[:, f])
                   for f, q in enumerate(qs_prev)]
        self._a = a

    @cached_property
    def qo(self) -> list:
        """Per modality, ``(K, num_obs[m])`` float predicted outcome distribution of each candidate."""
        a = self._a
        return [self._expect(a.live_A(m), a.A_deps[m], True) for m in range(len(a.A))]

    @cached_property
    def outcome_entropy(self) -> list:
        """Per modality, ``(K,)`` float entropy (nats) of the predicted outcome distribution."""
        return [entropy(qo, axis=1) for qo in self.qo]

    @cached_property
    def outcome_utility(self) -> list:
        """Per modality, ``(K,)`` float expected log-preference ``Q(o_m) . C_m``."""
        return [qo @ c for qo, c in zip(self.qo, self.C, strict=True)]

    @cached_property
    def ambiguity(self) -> list:
        """Per modality, ``(K,)`` float expected column entropy ``E_Q(s)[H[P(o_m|s)]]`` (nats)."""
        a = self._a
        return [self._expect(self.prep.HA[m], a.A_deps[m], False) for m in range(len(a.A))]

    @cached_property
    def a_novelty(self) -> list:
        """Per modality, ``(K,)`` float information gain about ``A``'s parameters, or None without counts."""
        a = self._a
        out = []
        for m, w in enumerate(self.prep.wA):
            if w is None:
                out.append(None)
            else:
                ew = self._expect(w, a.A_deps[m], True)
                out.append((self.qo[m] * ew).sum(axis=1))
        return out

    @cached_property
    def b_novelty(self) -> list:
        """Per factor, ``(K,)`` float information gain about ``B``'s parameters, or None without counts."""
        out = []
        deps = self._a.B_deps
        for f, w in enumerate(self.prep.wB):
            if w is None:
                out.append(None)
                continue
            u = self.actions[:, f]
            v = np.empty(self.num_candidates)
            for c in np.unique(u):
                rows = u == c
                if deps[f] == (f,):
                    v[rows] = ((self.qs[f][rows] @ w[:, :, c]) * self.qs_prev[f][rows]).sum(axis=1)
                else:  # the weights' expectation over the dependencies' previous beliefs, then the next state
                    ew = expect(w[..., c], [self.qs_prev[d][rows] for d in deps[f]], keep_first=True)
                    v[rows] = (self.qs[f][rows] * ew).sum(axis=1)
            out.append(v)
        return out

    @property
    def C_states(self) -> list:
        """Per factor, the ``(n_f,)`` float log-preferences over live states (None entries without any)."""
        a = self._a
        if a.C_states is None:
            return [None] * a.num_factors
        return [a.C_states[f][: a.num_states[f]] for f in range(a.num_factors)]

    @property
    def poses(self):
        """``(n, 2)`` float stored poses (metres) of the live states of the pose factor, or None."""
        a = self._a
        return None if a.poses is None else a.poses[: a.num_states[a.pose_factor]]

    @cached_property
    def view(self):
        """``(K,)`` float expected unseen fraction of the predicted state's view, or None without a view."""
        v = self._a.view
        if v is None:
            return None
        f = self._a.pose_factor
        return self.qs[f] @ v[: self._a.num_states[f]]

    def _goal_distances(self, dist):
        f = self._a.goal_factor
        return self.qs[f], dist, dist[self.qs_prev[f].argmax(axis=1)]


class LocalStep(_Common):
    """One planning step of a single sparse factor from a sparse prior, restricted to reachable states.

    Every array is over ``U`` (attribute), the states the candidates can reach, so the cost is
    independent of the size of the map.

    Parameters
    ----------
    prep : Prepared
        Derived quantities of the decision (local path).
    prior_idx : array_like
        ``(R,)`` int states with prior mass.
    prior_p : array_like
        ``(R,)`` float their probabilities (sum to 1).
    actions : array_like
        ``(K,)`` int control of each candidate.
    t : int, optional
        Index of the step within the imagined policy, default 0.
    collision : numpy.ndarray or None, optional
        ``(K,)`` float probability of a collision per candidate, or None.
    """

    def __init__(self, prep: Prepared, prior_idx, prior_p, actions, t: int = 0, collision=None):
        self.prep = prep
        self.t = t
        self.collision = collision
        a = prep.arrays
        self._a = a
        B = a.B[0]
        acts = np.asarray(actions, dtype=np.int64).reshape(-1)
        self.actions = acts[:, None]
        prior_idx = np.asarray(prior_idx, dtype=np.int64).reshape(-1)
        prior_p = np.asarray(prior_p, dtype=float).reshape(-1)
        self.prior_idx, self.prior_p = prior_idx, prior_p
        K, R = acts.size, prior_idx.size
        if R == 1:
            # point prior: the local space is the list of successor slots of each candidate
            # (a state may appear more than once; every term is linear in qs, so that is exact)
            s0 = prior_idx[0]
            succ = B.succ[s0, acts]  # (K, k)
            prob = B.prob[s0, acts] * prior_p[0]
            k = succ.shape[1]
            self.U = succ.ravel()
            self._inv = np.arange(K * k).reshape(1, K, k)
            qs = np.zeros((K, K * k))
            qs.reshape(K * K * k)[(np.arange(K) * (K * k + k))[:, None] + np.arange(k)] = prob
            self._point = True
        else:
            succ = B.succ[prior_idx[:, None], acts[None, :]]  # (R, K, k)
            prob = B.prob[prior_idx[:, None], acts[None, :]] * prior_p[:, None, None]
            U, inv = np.unique(succ, return_inverse=True)
            self.U = U
            self._inv = inv.reshape(succ.shape)
            nU = U.size
            flat = (np.arange(K)[None, :, None] * nU + self._inv).ravel()
            qs = np.bincount(flat, weights=prob.ravel(), minlength=K * nU).reshape(K, nU)
            self._point = False
        self.qs = [qs]

    @cached_property
    def qs_prev(self) -> list:
        """The prior as a (K, R) batch over its own support."""
        return [np.broadcast_to(self.prior_p, (self.num_candidates, self.prior_idx.size))]

    @cached_property
    def _outcomes(self) -> list:
        """Per modality: the predicted outcomes, compressed (``(bg, outcomes, values)``, see
        ``SparseLikelihood.mixture``; a dense likelihood lists every outcome)."""
        return [A.mixture(self.U, self.qs[0]) for A in self._a.A]

    @cached_property
    def _stats(self) -> list:
        """Per modality: column entropies and novelty weights of the states in ``U``."""
        return [self.prep.column_stats(m, self.U) for m in range(len(self._a.A))]

    @cached_property
    def qo(self) -> list:
        """Predicted outcome distributions, dense over every outcome (small models, tests)."""
        out = []
        for m, (bg, outcomes, values) in enumerate(self._outcomes):
            full = np.repeat(bg[:, None], self._a.num_obs[m], axis=1)
            full[:, outcomes] = values
            out.append(full)
        return out

    @cached_property
    def outcome_entropy(self) -> list:
        """Per modality, ``(K,)`` float entropy (nats) of the predicted outcome distribution."""
        return [-(self._a.num_obs[m] - outcomes.size) * xlogx(bg) - xlogx(values).sum(axis=1)
                for m, (bg, outcomes, values) in enumerate(self._outcomes)]

    @cached_property
    def outcome_utility(self) -> list:
        """Per modality, ``(K,)`` float expected log-preference ``Q(o_m) . C_m``."""
        a = self._a
        out = []
        for m, (bg, outcomes, values) in enumerate(self._outcomes):
            c = a.C[m][: a.num_obs[m]]
            rest = c.sum() - c[outcomes].sum() if outcomes.size < c.size else 0.0
            out.append(bg * rest + values @ c[outcomes])
        return out

    @cached_property
    def ambiguity(self) -> list:
        """Per modality, ``(K,)`` float expected column entropy ``E_Q(s)[H[P(o_m|s)]]`` (nats)."""
        return [self.qs[0] @ st[0] for st in self._stats]

    @cached_property
    def a_novelty(self) -> list:
        """Per modality, ``(K,)`` float information gain about ``A``'s parameters, or None without counts.

        ``sum_o Q(o) E_Q(s)[W(o, s)]`` from the compressed outcomes: every unlisted outcome shares the
        background weight of each column; listed slots add their difference.
        """
        qs = self.qs[0]
        out = []
        for m, A in enumerate(self._a.A):
            if not (self.prep.need_novelty and A.has_counts):
                out.append(None)
                continue
            bg, outcomes, values = self._outcomes[m]
            _, w_bg, w_slots = self._stats[m]
            wb = qs @ w_bg  # (K,) expected background weight
            diff = A.scatter_slots(self.U, outcomes, w_slots - w_bg[:, None])  # (U, listed outcomes)
            w_listed = wb[:, None] + qs @ diff
            rest = self._a.num_obs[m] - outcomes.size
            out.append(rest * bg * wb + (values * w_listed).sum(axis=1))
        return out

    @cached_property
    def b_novelty(self) -> list:
        """One-element list: ``(K,)`` float information gain about ``B``'s parameters, or None without counts."""
        B = self._a.B[0]
        if getattr(B, "counts", None) is None:
            return [None]
        from .efe import novelty_weights

        acts = self.actions[:, 0]
        K = acts.size
        if self._point:
            counts = B.counts[self.prior_idx[0], acts]  # (K, k)
            w = novelty_weights(counts, axis=1)
            succ = self.U.reshape(K, -1)
            q = self.qs[0].reshape(K * K, -1)[:: K + 1]  # each candidate's own slot block
            # predicted probability of each slot's state (slots may repeat a state)
            qn = ((succ[:, :, None] == succ[:, None, :]) * q[:, None, :]).sum(axis=2)
            return [(qn * w).sum(axis=1) * self.prior_p[0]]
        counts = B.counts[self.prior_idx[:, None], acts[None, :]]  # (R, K, k)
        w = novelty_weights(counts, axis=2)
        qn = self.qs[0][np.arange(K)[None, :, None], self._inv]  # predicted prob of each slot
        v = (self.prior_p[:, None, None] * qn * w).sum(axis=(0, 2))
        return [v]

    @cached_property
    def C_states(self) -> list:
        """One-element list: ``(U,)`` float log-preferences over the reachable states ``U`` (or None)."""
        a = self._a
        return [None if a.C_states is None else a.C_states[0][self.U]]

    @cached_property
    def poses(self):
        """``(U, 2)`` float stored poses (metres) of the reachable states ``U``, or None."""
        a = self._a
        return None if a.poses is None else a.poses[self.U]

    @cached_property
    def view(self):
        """``(K,)`` float expected unseen fraction of the predicted state's view, or None without a view."""
        v = self._a.view
        return None if v is None else self.qs[0] @ v[self.U]

    def _goal_distances(self, dist):
        anchor = self.prior_idx[self.prior_p.argmax()]
        return self.qs[0], dist[self.U], np.full(self.num_candidates, dist[anchor])

    def most_likely(self) -> np.ndarray:
        """Most likely next state per candidate (summing repeated states of a point prior).

        Returns
        -------
        numpy.ndarray
            ``(K,)`` int state indices.
        """
        if self._point:
            K = self.num_candidates
            succ = self.U.reshape(K, -1)
            q = self.qs[0].reshape(K * K, -1)[:: K + 1]
            tot = ((succ[:, :, None] == succ[:, None, :]) * q[:, None, :]).sum(axis=2)
            return succ[np.arange(K), tot.argmax(axis=1)]
        return self.U[self.qs[0].argmax(axis=1)]

"""Monte Carlo tree search over expected free energy (Appendix A.3).

Each simulation descends from the root for ``depth`` steps. At a node, the candidate actions
are the ones allowed there (moves with possible transitions; at the root, not flagged by the
obstacle signal); their one-step EFE ``g`` is computed once, in a batch, when the node is
expanded. Selection is UCB on the values: children not yet tried are tried first, best
immediate EFE first; after that, the child maximising ``(Q_max - Q) / (Q_max - Q_min) +
c sqrt(ln N / n)`` with ``Q`` the cumulative EFE backed up through it. The cumulative EFE of
the path below each edge is backed up along the path; an edge keeps the best (lowest) value
seen below it (``backup="min"``: the rollouts are deterministic expected-EFE sequences, so this
is the EFE of the best explored policy, as in exhaustive enumeration) or the mean
(``backup="mean"``, classic UCT). The decision is a softmax with precision ``gamma`` over the
root children's values (Eq. 4), taken by argmax
or sampled with the given ``numpy.random.Generator``; the search is deterministic given it.

Two expanders share this core:

* :class:`LocalExpander`: a single factor with sparse transitions (the topological map). Below
  the root a node is the most likely state; its expansion reads only the sparse columns of that
  state, so cost is independent of the map size. Expansions are shared through a transposition
  table keyed by the discrete state; visit statistics are keyed by ``(state, depth)`` so values
  of different remaining horizons are not mixed (``share="state"`` keys them by state only).
* :class:`BeliefExpander`: full (multi-factor) beliefs rolled forward exactly as policy
  enumeration does, with nodes shared by identical beliefs; with enough simulations it agrees
  with exhaustive enumeration.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .arrays import Prepared
from .context import DenseStep, LocalStep
from .efe import Objective
from .policies import enumerate_policies, softmax


@dataclass(frozen=True)
class MCTSConfig:
    """Settings of the MCTS over expected free energy (Appendix A.3 of the AIMAPP paper).

    Attributes
    ----------
    depth : int
        Steps per simulation, default 10 (Table 6 of the AIMAPP paper).
    simulations : int
        Simulations per decision, default 30 (Table 6).
    c : float
        UCB exploration constant (values are min-max normalised per node), default 1.
    gamma : float
        Precision of the decision softmax (Eq. 4), default 16.
    sample : bool
        Sample the decision instead of taking the argmax, default False.
    prune_obstacles : bool
        Do not expand root moves flagged by the obstacle signal, default True.
    move_threshold : float
        A move is allowed when the probability of leaving the state exceeds this, default 0.
    share : str
        Key of the visit statistics: ``"state_depth"`` (default) or ``"state"``.
    backup : str
        Edge value: ``"min"`` (best cumulative EFE seen below it, default) or ``"mean"`` (UCT).
    support_tol : float
        Root belief entries below ``support_tol * max`` are dropped (local path), default 1e-9.
    count_information_once : bool
        Count epistemic value once per imagined path (revisits gain nothing), default False.
    discount : float
        Discount of later steps' EFE, default 1 (the plain sum of Eq. 5).
    """
    depth: int = 10
    simulations: int = 30
    c: float = 1.0  # UCB exploration constant (values are min-max normalised per node)
    gamma: float = 16.0  # precision of the decision softmax
    sample: bool = False  # sample the decision instead of argmax
    prune_obstacles: bool = True  # do not expand root moves flagged by the obstacle signal
    move_threshold: float = 0.0  # a move is allowed when P(leave the state) exceeds this
    share: str = "state_depth"  # key of visit statistics: "state_depth" or "state"
    backup: str = "min"  # edge value: "min" (best cumulative EFE seen below it) or "mean"
    support_tol: float = 1e-9  # root belief entries below tol * max are dropped (local path)
    # With ``count_information_once``, epistemic value is counted once per imagined path:
    # returning to a state (or belief) already visited on the path gains no information again,
    # so back-and-forth paths cannot accumulate it (an exploring agent would otherwise oscillate
    # between two informative states). ``discount`` < 1 then prefers information gained sooner.
    # The defaults are the plain sum of Eq. 5.
    count_information_once: bool = False
    discount: float = 1.0


class Node:
    __slots__ = ("actions", "g", "g_known", "child", "n", "w", "best", "N", "tie", "order", "tried")

    def __init__(self, actions, g, child, tie, g_known=None):
        self.actions = actions
        self.g = g
        self.g_known = g if g_known is None else g_known  # step value when its outcome is already known
        self.child = child
        self.n = np.zeros(len(g))
        self.w = np.zeros(len(g))
        self.best = np.full(len(g), np.inf)
        self.N = 0
        self.tie = tie
        self.order = np.argsort(g + tie, kind="stable").tolist()  # untried: best g first
        self.tried = 0

    def select(self, c: float, use_min: bool = True) -> int:
        """Same rule as :func:`ucb_select`, with the untried children taken in order."""
        if self.tried < len(self.order):
            i = self.order[self.tried]
            self.tried += 1
            return i
        n = self.n
        Q = self.best if use_min else self.w / n
        lo, hi = Q.min(), Q.max()
        span = hi - lo if hi > lo else 1.0
        score = (hi - Q) / span + c * np.sqrt(math.log(max(self.N, 1)) / n) - self.tie
        return int(score.argmax())


def ucb_select(n: np.ndarray, w: np.ndarray, g: np.ndarray, N: int, c: float, tie=None) -> int:
    """UCB over EFE: which child of a node to descend into.

    Untried children first (lowest immediate EFE ``g``); then the child maximising the normalised
    value ``(Q_max - Q) / (Q_max - Q_min)`` plus ``c sqrt(ln N / n)``, where ``Q = w / n`` is the mean
    cumulative EFE (lower is better).

    Parameters
    ----------
    n : numpy.ndarray
        ``(K,)`` float visit count per child.
    w : numpy.ndarray
        ``(K,)`` float summed cumulative EFE per child.
    g : numpy.ndarray
        ``(K,)`` float immediate EFE per child.
    N : int
        Visits of the node.
    c : float
        Exploration constant.
    tie : numpy.ndarray or float, optional
        Tiny per-child tie-breaking offsets (subtracted from the score).

    Returns
    -------
    int
        Index of the chosen child.
    """
    tie = 0.0 if tie is None else tie
    untried = n == 0
    if untried.any():
        return int(np.argmin(np.where(untried, g + tie, np.inf)))
    Q = w / n
    lo, hi = Q.min(), Q.max()
    span = hi - lo if hi > lo else 1.0
    score = (hi - Q) / span + c * np.sqrt(math.log(max(N, 1)) / n) - tie
    return int(np.argmax(score))


@dataclass
class SearchResult:
    """The outcome of one tree search: the chosen control and the statistics of the root candidates.

    Attributes
    ----------
    action : int or tuple of int
        Control (or one control per factor) to execute.
    actions : numpy.ndarray
        Root candidate controls.
    probs : numpy.ndarray
        ``(K,)`` float decision distribution over the root candidates (softmax of ``-gamma Q``).
    Q : numpy.ndarray
        ``(K,)`` float backed-up cumulative EFE per root candidate (nan if never visited).
    visits : numpy.ndarray
        ``(K,)`` float visits per root candidate.
    G_first : numpy.ndarray
        ``(K,)`` float one-step EFE per root candidate.
    info : dict
        ``"nodes"`` (tree size) and ``"expansions"`` (local expander's count, else None).
    """
    action: int | tuple  # control (or tuple of controls per factor) to execute
    actions: np.ndarray  # root candidate controls
    probs: np.ndarray  # decision distribution over root candidates
    Q: np.ndarray  # backed-up cumulative EFE per root candidate (nan if never visited)
    visits: np.ndarray
    G_first: np.ndarray  # one-step EFE per root candidate
    info: dict = field(default_factory=dict)


def allowed_actions(B, s: int, stay: int | None, threshold: float = 0.0) -> np.ndarray:
    """Controls at state ``s`` of a sparse B whose transitions can leave ``s`` (plus stay)."""
    succ, prob = B.succ[s], B.prob[s]
    leave = (prob * (succ != s)).sum(axis=1) > threshold
    if stay is not None:
        leave[stay] = True
    acts = np.flatnonzero(leave)
    return acts if acts.size else np.arange(succ.shape[0])


class LocalExpander:
    """Expansion on a single sparse factor (see module docstring)."""

    def __init__(self, prep: Prepared, objective: Objective, prior_idx, prior_p, obstacles, cfg):
        self.prep, self.objective, self.cfg = prep, objective, cfg
        a = prep.arrays
        self.B = a.B[0]
        self.stay = None if a.stay is None else a.stay[0]
        p = np.asarray(prior_p, dtype=float)
        self.prior_idx = np.asarray(prior_idx, dtype=np.int64)
        self.prior_p = p / p.sum()
        self.obstacles = None if obstacles is None else np.asarray(obstacles, dtype=float)
        self.cache: dict = {}
        self.expansions = 0

    def root(self):
        anchor = int(self.prior_idx[self.prior_p.argmax()])
        acts = allowed_actions(self.B, anchor, self.stay, self.cfg.move_threshold)
        coll = None
        if self.obstacles is not None:
            if self.cfg.prune_obstacles:
                free = acts[self.obstacles[acts] <= 0.0]
                if free.size:
                    acts = free
            coll = self.obstacles[acts]
        ctx = LocalStep(self.prep, self.prior_idx, self.prior_p, acts, 0, coll)
        self.expansions += 1
        self.root_key = anchor
        return (acts, *self.objective.split(ctx), ctx.most_likely().tolist())

    def expand(self, s: int):
        hit = self.cache.get(s)
        if hit is None:
            acts = allowed_actions(self.B, s, self.stay, self.cfg.move_threshold)
            ctx = LocalStep(self.prep, (s,), (1.0,), acts, 1, None)
            hit = (acts, *self.objective.split(ctx), ctx.most_likely().tolist())
            self.cache[s] = hit
            self.expansions += 1
        return hit


class BeliefExpander:
    """Expansion on full factor beliefs (dense), nodes shared by identical beliefs."""

    def __init__(self, prep: Prepared, objective: Objective, qs, obstacles, cfg):
        self.prep, self.objective, self.cfg = prep, objective, cfg
        a = prep.arrays
        self.controls = enumerate_policies(a.num_controls, 1)[:, 0, :]
        self.obstacles = None if obstacles is None else np.asarray(obstacles, dtype=float)
        self.beliefs: list = []
        self.ids: dict = {}
        self.cache: dict = {}
        self.expansions = 0
        self.root_q = [np.asarray(q, dtype=float)[: a.num_states[f]] for f, q in enumerate(qs)]

    def _key(self, qs) -> int:
        h = b"".join(np.round(q, 12).tobytes() for q in qs)
        k = self.ids.get(h)
        if k is None:
            k = len(self.beliefs)
            self.ids[h] = k
            self.beliefs.append(qs)
        return k

    def _step(self, qs, acts, coll):
        K = len(acts)
        ctx = DenseStep(self.prep, [np.broadcast_to(q, (K, q.size)) for q in qs], acts, 0, coll)
        g, g_known = self.objective.split(ctx)
        kids = [self._key([q[k] for q in ctx.qs]) for k in range(K)]
        self.expansions += 1
        return acts, g, g_known, kids

    def root(self):
        acts = self.controls
        coll = None
        if self.obstacles is not None:
            cf = self.prep.arrays.control_factor
            if self.cfg.prune_obstacles:
                free = acts[self.obstacles[acts[:, cf]] <= 0.0]
                if len(free):
                    acts = free
            coll = self.obstacles[acts[:, cf]]
        self.root_key = self._key(self.root_q)
        return self._step(self.root_q, acts, coll)

    def expand(self, key: int):
        hit = self.cache.get(key)
        if hit is None:
            hit = self._step(self.beliefs[key], self.controls, None)
            self.cache[key] = hit
        return hit


def search(expander, cfg: MCTSConfig, rng: np.random.Generator) -> SearchResult:
    """Run ``cfg.simulations`` simulations of ``cfg.depth`` steps and decide."""
    acts, g, g_known, kids = expander.root()
    root = Node(acts, g, kids, rng.random(len(g)) * 1e-9, g_known)
    nodes: dict = {}
    by_state = cfg.share == "state"
    use_min = cfg.backup == "min"
    for _ in range(cfg.simulations):
        node = root
        path = []
        seen = {expander.root_key}  # information at a state seen earlier on this path is known
        for d in range(cfg.depth):
            i = node.select(cfg.c, use_min)
            key = node.child[i]
            path.append((node, i, cfg.count_information_once and key in seen))
            seen.add(key)
            if d + 1 == cfg.depth:
                break
            nk = key if by_state else (key, d + 1)
            nxt = nodes.get(nk)
            if nxt is None:
                a2, g2, gk2, k2 = expander.expand(key)
                nxt = Node(a2, g2, k2, rng.random(len(g2)) * 1e-9, gk2)
                nodes[nk] = nxt
            node = nxt
        ret = 0.0
        for node, i, known in reversed(path):
            ret = (node.g_known[i] if known else node.g[i]) + cfg.discount * ret
            node.n[i] += 1.0
            node.w[i] += ret
            if ret < node.best[i]:
                node.best[i] = ret
            node.N += 1
    visited = root.n > 0
    Q = np.full(len(root.g), np.nan)
    Q[visited] = (root.best if use_min else root.w / np.maximum(root.n, 1))[visited]
    probs = np.zeros(len(root.g))
    if visited.any():
        probs[visited] = softmax(-cfg.gamma * Q[visited])
    else:
        probs[int(np.argmin(root.g))] = 1.0
    i = int(rng.choice(len(probs), p=probs)) if cfg.sample else int(np.argmax(probs))
    a = root.actions[i]
    action = int(a) if np.ndim(a) == 0 else tuple(int(x) for x in a)
    return SearchResult(
        action=action,
        actions=root.actions,
        probs=probs,
        Q=Q,
        visits=root.n.copy(),
        G_first=root.g,
        info={"nodes": len(nodes) + 1, "expansions": getattr(expander, "expansions", None)},
    )


def mcts(
    prep: Prepared,
    qs,
    objective: Objective,
    obstacles=None,
    config: MCTSConfig | None = None,
    rng: np.random.Generator | int | None = None,
) -> SearchResult:
    """MCTS decision from a belief: a tree over states (one sparse factor) or over full beliefs.

    Parameters
    ----------
    prep : Prepared
        Derived arrays of the decision; a local preparation selects the state tree.
    qs : list of numpy.ndarray
        Current belief per factor, ``(n_f,)`` float.
    objective : Objective
        Per-step EFE.
    obstacles : array_like, optional
        Per control, True (or a probability) where an obstacle blocks that direction.
    config : MCTSConfig, optional
        Search settings; default ``MCTSConfig()``.
    rng : numpy.random.Generator or int or None, optional
        Random generator or seed (tie-breaking and sampling); the search is deterministic given it.

    Returns
    -------
    SearchResult

    Notes
    -----
    Appendix A.3 of the AIMAPP paper; the decision is Eq. (4) over the root children's values.
    """
    if getattr(prep.arrays, "has_B_deps", False):
        raise ValueError("mcts does not support transitions that depend on several factors (B_dependencies) "
                         "yet; use the policy planner (evaluate_policies) for such models")
    cfg = config or MCTSConfig()
    rng = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
    if prep.local:
        q = np.asarray(qs[0], dtype=float)[: prep.arrays.num_states[0]]
        idx = np.flatnonzero(q > cfg.support_tol * q.max())
        expander = LocalExpander(prep, objective, idx, q[idx], obstacles, cfg)
    else:
        expander = BeliefExpander(prep, objective, qs, obstacles, cfg)
    return search(expander, cfg, rng)

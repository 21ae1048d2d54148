"""The agent's planning call: MCTS over EFE in exploration or goal mode."""

from __future__ import annotations

import numpy as np

from cogmap.planning import efe, sensed
from cogmap.planning import inductive as ind
from cogmap.planning.arrays import from_model, prepare
from cogmap.planning.context import LocalStep
from cogmap.planning.decide import decide as mcts_decide

from .map_growth import state_poses


def _target(model, cfg, views, seen_from: np.ndarray, state: int, areas: np.ndarray) -> np.ndarray:
    """The preferred state of the inductive term while exploring (docs/exploration.md).

    Viewpoints are the informative unvisited states and frontier points (``ViewMap.viewpoints``),
    plus the sources of believed transitions that the latest scan shows blocked (worth
    ``view_min_area``). They are ranked by unseen area per metre of path from the robot over its
    sensed free space (the oracle's rule, :func:`sensed.rank_viewpoints`, with hysteresis). For
    the best ``view_tries`` of them in turn, the state with the shortest rest of the way to the
    viewpoint (a metre of believed-possible path to that state counting ``view_path_weight``
    metres, :func:`sensed.state_toward`) is preferred, so Eq. 9 pulls MCTS toward the viewpoint
    from however far away. A viewpoint for which that state is the robot's own is set aside until
    a new state of the map lies nearer to it (the robot stands as near to it as the map allows;
    nothing is set aside while the LiDAR is silent, since the map cannot grow then), as the oracle's viewpoints
    are once stood on. Empty when no viewpoint is left or none is brought nearer; then
    ``views.pursuit.unreached`` counts the viewpoints and the paper's terms alone decide."""
    B, n = model.B[0], model.num_states[0]
    aim = views.pursuit
    poses, visited = state_poses(model), np.asarray(seen_from[:n], dtype=bool)
    xy, gains = views.viewpoints(poses, visited, areas)
    src, dst = B.edges(cfg.inductive_threshold, n)
    doubt = views.doubtful(poses, src, dst, state)
    if doubt.size:  # a believed transition crosses a newly sensed obstacle: its source has information
        xy = np.vstack([xy, poses[doubt]])
        gains = np.concatenate([gains, np.full(doubt.size, cfg.view_min_area)])
    aim.target, aim.unreached = -1, 0
    if gains.size == 0:
        aim.viewpoint = None
        return np.zeros(0, dtype=np.int64)
    grid = views.grid
    path = sensed.lookup_near(grid, sensed.path_lengths(grid, poses[state]), xy)
    keep = -1
    if aim.viewpoint is not None:
        d = np.hypot(*(xy - aim.viewpoint).T)
        keep = int(np.argmin(d)) if d.min() <= cfg.view_keep_radius else -1
    order = sensed.rank_viewpoints(gains, path, cfg.view_detour, keep=keep, keep_ratio=cfg.view_keep_ratio)
    steps = ind.goal_distances(dst, src, np.array([state]), n, cfg.inductive_depth).astype(float)
    steps[steps >= ind.UNREACHABLE] = np.inf
    if aim.spent_at != n:  # the map changed: a viewpoint comes back when a new state lies nearer to it
        aim.spent = _revive(aim.spent, poses[aim.spent_at:n] if n > aim.spent_at else None, cfg.view_keep_radius)
        aim.spent_at = n
    if aim.spent:  # set-aside viewpoints do not use up the tries
        order = order[~sensed.near_any(xy[order], np.array([p for p, _ in aim.spent]), 0.3)]
    for j in order[: cfg.view_tries]:
        # the state with the shortest rest of the way to the viewpoint, a metre of believed path
        # to it counting view_path_weight metres; none but the robot's own: set it aside
        way = sensed.lookup_near(grid, sensed.path_lengths(grid, xy[j]), poses)
        s = sensed.state_toward(way, steps, cfg.influence_radius, cfg.view_path_weight)
        if s >= 0 and s != state:
            aim.viewpoint, aim.target = xy[j].copy(), s
            return np.array([s])
        if not aim.blind:  # without the LiDAR the map cannot grow toward it: not a reason to give up
            aim.spent.append((xy[j].copy(), float(np.hypot(*(poses - xy[j]).T).min())))
    aim.viewpoint, aim.unreached = None, int(order.size)  # viewpoints with a path, none brought nearer
    return np.zeros(0, dtype=np.int64)


def _revive(spent: list, new_poses, margin: float) -> list:
    """The set-aside viewpoints ``(xy, distance of the nearest state then)`` that stay set aside
    after the map changed: all of them are revived when states were removed (``new_poses`` None),
    and one is revived when a new state lies more than ``margin`` nearer to it than any state did
    (so the robot can now stand nearer), not merely because the map grew elsewhere."""
    if new_poses is None:
        return []
    if len(new_poses) == 0:
        return spent
    return [(p, near) for p, near in spent if np.hypot(*(new_poses - p).T).min() >= near - margin]


def decide(model, cfg, q: np.ndarray, rng: np.random.Generator, views, seen_from: np.ndarray, goals, state: int,
           obstacles, mode: str) -> tuple[int, dict]:
    """One MCTS decision over expected free energy (Appendix A.3), exploring or in goal mode.

    Parameters
    ----------
    model : cogmap.genmodel.Model
        The map.
    cfg : AgentConfig
        The agent's parameters (``cfg.mcts`` goes to the search as it is).
    q : numpy.ndarray
        ``(num_states,)`` current belief.
    rng : numpy.random.Generator
        The search's generator.
    views : ViewMap
        What the LiDAR has sensed (exploration's view weighting and target).
    seen_from : numpy.ndarray
        ``(num_states,)`` bool: states stood on with the LiDAR reporting.
    goals : numpy.ndarray or None
        Goal states in goal mode.
    state : int
        The state believed.
    obstacles : numpy.ndarray
        ``(num_headings,)`` bool collision flag per heading.
    mode : str
        ``"explore"`` or ``"goal"``.

    Returns
    -------
    action : int
        The control.
    summary : dict
        Root ``actions``, ``Q``, ``visits``, the ``objective``, the planning ``arrays``, the
        ``obstacles`` flags (stay appended) and, while a view-weighted target is pursued, the
        ``preferred`` states.
    """
    n = model.num_states[0]
    obstacles = np.asarray(obstacles, dtype=bool)
    view = None
    if mode == "goal":  # preferences C (set by the agent's goal) weighted 10, inductive term, collision
        objective = efe.goal(goal_weight=cfg.goal_weight, inductive_weight=cfg.inductive_weight)
        goal_states = goals
    else:
        objective, goal_states = efe.exploration(), None
        areas = views.areas(state_poses(model), seen_from) if cfg.view_weighting else None
        if areas is not None:  # what the LiDAR has sensed weights the information gain; informative views pull
            goal_states = _target(model, cfg, views, seen_from, state, areas)
            if goal_states.size:
                objective = efe.sensed_exploration(inductive_weight=cfg.explore_inductive_weight)
                view = views.fractions(areas)
            # else: nothing reachable is left unseen; the paper's terms alone (the model still learns)
    # The stay control never collides, but standing still gains nothing while exploring, nor in goal
    # mode away from a goal state: its subtree holds every move one step later, so with few
    # simulations MCTS can value it like the best move after it and the robot waits for good
    # (observed: 60 decisions in place). It is offered in goal mode at a goal state, or when no
    # move is free.
    at_goal = mode == "goal" and (bool(np.isin(state, goal_states)) or obstacles.all())
    obstacles = np.append(obstacles, not at_goal)
    arrays = from_model(model, goal_states=goal_states, view=view, collision_pref=cfg.collision_preference)
    d = mcts_decide(arrays, [q[:n]], obstacles, objective, config=cfg.mcts, rng=rng)
    out = {"actions": d.actions, "Q": d.Q, "visits": d.visits, "objective": objective, "arrays": arrays,
           "obstacles": obstacles}
    if view is not None:
        out["preferred"] = goal_states
    return int(d.action), out


def term_breakdown(q: np.ndarray, efe_summary: dict, action: int) -> dict[str, float]:
    """Weighted contribution of every EFE term to the first step of ``action`` (same sign as G:
    negative is attractive), as the last decision's objective saw it. Call it right after the
    decision (the model keeps learning)."""
    arrays, objective = efe_summary["arrays"], efe_summary["objective"]
    prep = prepare(arrays, local=True)
    q = np.asarray(q[: arrays.num_states[0]], dtype=float)
    idx = np.flatnonzero(q > 1e-9 * q.max())
    coll = np.asarray(efe_summary["obstacles"], dtype=float)[[action]]
    ctx = LocalStep(prep, idx, q[idx] / q[idx].sum(), np.array([action]), 0, coll)
    return {k: float(v[0]) for k, v in objective.breakdown(ctx).items()}

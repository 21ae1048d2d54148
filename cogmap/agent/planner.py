"""The agent's planning call: MCTS over EFE in exploration or goal mode."""

from __future__ import annotations

import numpy as np

from cogmap.planning import efe, sensed
from cogmap.planning import inductive as ind
from cogmap.planning.arrays import from_model, prepare
from cogmap.planning.context import LocalStep
from cogmap.planning.decide import decide as mcts_decide
from cogmap.planning.mcts import MCTSConfig


def _target(agent, state: int, states: np.ndarray, gains: np.ndarray, beyond: np.ndarray) -> np.ndarray:
    """The preferred state of the inductive term while exploring: among the states that still
    promise information, the one with the most unseen area per metre of believed-possible path
    from ``state`` (plus ``beyond``, the way from that state to the view that promises it).
    Sources of believed transitions that the latest scan shows blocked count as candidates too
    (worth ``view_min_area``). Empty when none is reachable within the inductive depth."""
    cfg, B, n = agent.cfg, agent.model.B[0], agent.num_states
    src, dst = B.edges(cfg.inductive_threshold, n)
    doubt = agent.views.doubtful(agent.poses, src, dst, state)
    if doubt.size:  # a believed transition crosses a newly sensed obstacle: its source has information
        states = np.concatenate([states, doubt])
        gains = np.concatenate([gains, np.full(doubt.size, cfg.view_min_area)])
        beyond = np.concatenate([beyond, np.zeros(doubt.size)])
    if states.size == 0:
        agent.views.target, agent.views.unreached = -1, 0
        return states
    steps = ind.goal_distances(dst, src, np.array([state]), n, cfg.inductive_depth)[states].astype(float)
    steps[steps >= ind.UNREACHABLE] = np.inf
    last = agent.views.target
    keep = int(np.flatnonzero(states == last)[0]) if last >= 0 and (states == last).any() else -1
    i = sensed.best_target(gains, steps + beyond / cfg.influence_radius, cfg.influence_radius, cfg.view_detour,
                           keep=keep, keep_ratio=cfg.view_keep_ratio)
    agent.views.target = int(states[i]) if i >= 0 else -1
    agent.views.unreached = int(states.size) if i < 0 else 0  # informative states without a believed path
    return states[i:i + 1] if i >= 0 else states[:0]


def decide(agent, state: int, obstacles, mode: str) -> tuple[int, dict]:
    """Return (control, summary) for the agent's current belief ``agent.q``."""
    cfg, model = agent.cfg, agent.model
    n = model.num_states[0]
    # The stay control never collides, but standing still gains nothing while exploring (MCTS
    # would value it like the best move after it): it is offered in goal mode only.
    obstacles = np.append(np.asarray(obstacles, dtype=bool), mode != "goal")
    mcfg = MCTSConfig(depth=cfg.mcts_depth, simulations=cfg.mcts_simulations, gamma=cfg.gamma,
                      move_threshold=cfg.min_move_probability, count_information_once=cfg.mcts_count_information_once,
                      discount=cfg.mcts_discount)
    view = None
    if mode == "goal":  # preferences C (set by the agent's goal) weighted 10, inductive term, collision
        objective = efe.goal(goal_weight=cfg.goal_weight, inductive_weight=cfg.inductive_weight)
        goal_states = agent.goal_states()
    else:
        objective, goal_states = efe.exploration(), None
        views, seen_from = agent.views, agent.scanned_from()
        areas = views.areas(agent.poses, seen_from) if cfg.view_weighting else None
        if areas is not None:  # what the LiDAR has sensed weights the information gain; informative states pull
            goal_states = _target(agent, state, *views.candidates(agent.poses, seen_from, areas))
            if goal_states.size:
                objective = efe.sensed_exploration(inductive_weight=cfg.explore_inductive_weight)
                view = views.fractions(areas)
            # else: nothing reachable is left unseen; the paper's terms alone (the model still learns)
    arrays = from_model(model, goal_states=goal_states, view=view, collision_pref=cfg.collision_preference)
    d = mcts_decide(arrays, [agent.q[:n]], obstacles, objective, config=mcfg, rng=agent.rng)
    out = {"actions": d.actions, "Q": d.Q, "visits": d.visits, "objective": objective, "arrays": arrays,
           "obstacles": obstacles}
    if view is not None:
        out["preferred"] = goal_states
    return int(d.action), out


def term_breakdown(agent, efe_summary: dict, action: int) -> dict[str, float]:
    """Weighted contribution of every EFE term to the first step of ``action`` (same sign as G:
    negative is attractive), as the last decision's objective saw it. Call it right after the
    decision (the model keeps learning)."""
    arrays, objective = efe_summary["arrays"], efe_summary["objective"]
    prep = prepare(arrays, local=True)
    q = np.asarray(agent.q[: arrays.num_states[0]], dtype=float)
    idx = np.flatnonzero(q > 1e-9 * q.max())
    coll = np.asarray(efe_summary["obstacles"], dtype=float)[[action]]
    ctx = LocalStep(prep, idx, q[idx] / q[idx].sum(), np.array([action]), 0, coll)
    return {k: float(v[0]) for k, v in objective.breakdown(ctx).items()}

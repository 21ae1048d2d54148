"""The agent's planning call: MCTS over EFE in exploration or goal mode."""

from __future__ import annotations

import numpy as np

from cogmap.planning import efe
from cogmap.planning.decide import decide as mcts_decide
from cogmap.planning.mcts import MCTSConfig


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
    if mode == "goal":  # preferences C (set by the agent's goal) weighted 10, inductive term, collision
        objective = efe.goal(goal_weight=cfg.goal_weight, inductive_weight=cfg.inductive_weight)
        goal_states = agent.goal_states()
    else:
        objective, goal_states = efe.exploration(), None
    d = mcts_decide(model, [agent.q[:n]], obstacles, objective, goal_states=goal_states, config=mcfg, rng=agent.rng)
    return int(d.action), {"actions": d.actions, "Q": d.Q, "visits": d.visits}

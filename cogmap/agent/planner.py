"""The agent's planning call: MCTS over EFE in exploration, goal or re-localisation mode."""

from __future__ import annotations

import numpy as np

from cogmap.planning import efe
from cogmap.planning.decide import decide as mcts_decide
from cogmap.planning.mcts import MCTSConfig

# Re-localisation: resolve uncertainty about where we are (state information gain) while
# moving toward places already seen (state preference on visited states), avoiding obstacles.
RELOCALISE = efe.objective([(efe.state_info_gain, 1.0), (efe.state_preference, 1.0), (efe.collision, 1.0)])


def visited_states(agent) -> np.ndarray:
    """States whose observation model has been taught at least once."""
    return agent.model.live_pA(0).max(axis=0) > 2 * agent.cfg.prior_count


def decide(agent, state: int, obstacles, mode: str) -> tuple[int, dict]:
    """Return (control, summary) for the agent's current belief ``agent.q``."""
    cfg, model = agent.cfg, agent.model
    n = model.num_states[0]
    # The stay control never collides, but standing still gains nothing while exploring or
    # re-localising (MCTS would value it like the best move after it): it is offered in goal mode only.
    obstacles = np.append(np.asarray(obstacles, dtype=bool), mode != "goal")
    mcfg = MCTSConfig(depth=cfg.mcts_depth, simulations=cfg.mcts_simulations, gamma=cfg.gamma,
                      move_threshold=cfg.min_move_probability)
    C_states, C_obs = model.C_states[0], model.C[0]
    C_states[:n] = 0.0
    C_obs[: model.num_obs[0]] = 0.0
    goal_states = None
    if mode == "goal":
        C_obs[agent.goal_obs] = 1.0  # weighted by the goal preference weight in the objective
        goal_states = agent.goal_states()
        objective = efe.goal(goal_weight=cfg.goal_weight)
    elif mode == "relocalise":
        C_states[:n] = visited_states(agent).astype(float)
        goal_states = np.zeros(0, dtype=int)
        objective = RELOCALISE
    else:
        objective = efe.exploration()
    try:
        d = mcts_decide(model, [agent.q[:n]], obstacles, objective, goal_states=goal_states, config=mcfg,
                        rng=agent.rng)
    finally:
        C_states[:n] = 0.0
        C_obs[: model.num_obs[0]] = 0.0
    return int(d.action), {"actions": d.actions, "Q": d.Q, "visits": d.visits}

"""cogmap.planning: expected-free-energy terms, policies, MCTS, the inductive term and A*.

An agent loop makes one decision with :func:`decide`::

    from cogmap.planning import decide, MCTSConfig
    d = decide(model, qs, obstacles=flags, mode="explore", rng=rng)
    action = d.action

Lower-level pieces are pure functions of arrays: :mod:`.efe` (terms, :func:`objective`,
presets), :mod:`.policies` (enumeration, rollouts, softmax selection), :mod:`.action_selection`
(habits, action precision, the control probabilities a subject's choice is scored by), :mod:`.mcts`,
:mod:`.inductive`, :mod:`.astar`, :mod:`.sophisticated` (expected free energy recursed over actions and
outcomes). Extension points: :func:`register_term` (an EFE term usable by
name in :func:`objective`) and :func:`register_planner` (a planner the agent loop finds by name).
"""

from . import action_selection, efe, inductive
from .action_selection import control_probabilities, select_action
from .arrays import PlanningArrays, Prepared, from_model, prepare
from .astar import astar_graph, astar_grid
from .context import DenseStep, LocalStep
from .decide import decide, make_objective
from .efe import (
    Objective,
    a_novelty,
    available_terms,
    b_novelty,
    collision,
    exploration,
    full,
    goal,
    objective,
    observation_preference,
    param_info_gain,
    position_preference,
    register_term,
    state_info_gain,
    state_preference,
    unregister_term,
)
from .mcts import MCTSConfig, SearchResult, mcts, ucb_select
from .planners import (
    Plan,
    PlanSettings,
    accepting_planners,
    available_planners,
    get_planner,
    register_planner,
    unregister_planner,
)
from .policies import (
    enumerate_policies,
    evaluate_policies,
    infer_policies,
    policy_posterior,
    select,
)
from .sophisticated import SophisticatedConfig, sophisticated_efe

__all__ = [
    "action_selection",
    "control_probabilities",
    "select_action",
    "SearchResult",
    "DenseStep",
    "LocalStep",
    "MCTSConfig",
    "Objective",
    "Plan",
    "PlanSettings",
    "PlanningArrays",
    "Prepared",
    "a_novelty",
    "astar_graph",
    "astar_grid",
    "accepting_planners",
    "available_planners",
    "available_terms",
    "b_novelty",
    "collision",
    "decide",
    "efe",
    "enumerate_policies",
    "evaluate_policies",
    "exploration",
    "from_model",
    "full",
    "get_planner",
    "goal",
    "inductive",
    "infer_policies",
    "make_objective",
    "mcts",
    "objective",
    "observation_preference",
    "param_info_gain",
    "position_preference",
    "prepare",
    "register_planner",
    "register_term",
    "select",
    "policy_posterior",
    "sophisticated_efe",
    "SophisticatedConfig",
    "state_info_gain",
    "state_preference",
    "ucb_select",
    "unregister_planner",
    "unregister_term",
]

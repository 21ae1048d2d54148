"""The drone methods of the studies: each name's policy (the hierarchical AIF agent, its
ablations and the two baselines). The episode itself is :mod:`cogmap.envs.drone_episode`."""

from __future__ import annotations

__all__ = ["METHODS", "make_policy"]


def make_policy(method: str, seed: int = 0):
    """The policy of a drone method name.

    Parameters
    ----------
    method : str
        ``"agent"`` (hierarchical AIF), ``"agent_published"`` (the published planner, without the
        novelty, path clearance, tie keeping and contact memory of ``"agent"``),
        ``"agent_persistent"`` (beliefs kept across steps), ``"no_filter"``, ``"no_epistemic"``,
        ``"no_novelty"`` (the paper's EFE, not discounted at visited places), ``"agent_depth2"`` /
        ``"agent_depth3"`` (EFE over
        waypoint sequences), ``"straight"`` or ``"potential"``.
    seed : int, optional
        Seed of the agent's planner, default 0 (unused by the baselines).

    Returns
    -------
    DroneAgent or StraightLine or PotentialField

    Raises
    ------
    ValueError
        For an unknown method.
    """
    from dataclasses import replace

    from cogmap.planning.drone_policies import PotentialField, StraightLine

    from .agent import DroneAgent, DroneAgentConfig


    base = DroneAgentConfig()
    if method == "agent":
        return DroneAgent(base, seed)
    if method == "agent_published":
        return DroneAgent(DroneAgentConfig.published(), seed)
    if method == "agent_persistent":
        return DroneAgent(replace(base, persistent_beliefs=True), seed)
    if method == "no_filter":
        return DroneAgent(replace(base, planner=replace(base.planner, use_filter=False)), seed)
    if method == "no_epistemic":
        return DroneAgent(replace(base, planner=replace(base.planner, w_epistemic=0.0)), seed)
    if method == "no_novelty":
        return DroneAgent(replace(base, planner=replace(base.planner, novelty=False)), seed)
    if method in ("agent_depth2", "agent_depth3"):
        return DroneAgent(replace(base, depth=int(method[-1])), seed)
    if method == "straight":
        return StraightLine()
    if method == "potential":
        return PotentialField()
    raise ValueError(f"unknown drone method {method!r}; choose from {METHODS}")


METHODS = ("agent", "agent_published", "agent_persistent", "no_filter", "no_epistemic", "no_novelty", "agent_depth2",
           "agent_depth3", "straight", "potential")

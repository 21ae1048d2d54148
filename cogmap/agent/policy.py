"""The AIMAPP agent as a :class:`cogmap.harness.Policy`: what it senses from a ``NavSim`` and
how its decision becomes a motion command and a trajectory row."""

from __future__ import annotations

import numpy as np

from cogmap.harness import Command

from .aimapp import AIMAPPAgent, Sensed
from .config import AgentConfig
from .sensing import corridor_obstacles, scan_points, sweep_points


def sense(sim, moved: bool | None, cfg: AgentConfig) -> Sensed:
    """Panorama, odometry and the corridor obstacle signal (odometry frame) from the robot."""
    ranges, odom = sim.lidar(), sim.odometry()
    obstacles = points = sweep = None
    if ranges is not None and odom is not None:
        angles = sim.lidar_angles() + odom[2]  # beams in the odometry frame
        obstacles = corridor_obstacles(ranges, angles, cfg.num_headings, cfg.influence_radius,
                                       cfg.robot_radius + cfg.obstacle_margin, sim.config.lidar_range)
        points = scan_points(ranges, angles, sim.config.lidar_range)
        sweep = sweep_points(ranges, angles, sim.config.lidar_range)
    return Sensed(sim.panorama(), obstacles, odom, moved, points, sweep)


class AgentPolicy:
    """Senses panorama, LiDAR and odometry; one decision is one :meth:`AIMAPPAgent.step`."""

    label = "explore"

    def __init__(self, agent: AIMAPPAgent):
        self.agent = agent

    def sense(self, sim, moved: bool | None) -> Sensed:
        return sense(sim, moved, self.agent.cfg)

    def step(self, sensed: Sensed) -> Command:
        agent = self.agent
        d = agent.step(sensed)
        odom = sensed.odometry
        belief = agent.believed_pose_yaw(odom) if odom is not None else np.full(3, np.nan)
        row = dict(belief_x=belief[0], belief_y=belief[1], belief_yaw=belief[2], state=d.state, action=d.action,
                   mode=d.mode, missing="+".join(d.missing), num_states=agent.num_states,
                   num_obs=0 if agent.model is None else agent.model.num_obs[0])
        status = dict(states=agent.num_states, mode=d.mode[:5] + ("-" + "/".join(d.missing) if d.missing else ""))
        waypoint = None if d.action == agent.cfg.stay else d.waypoint
        return Command(waypoint, "odom", row, status=status, decision=d)

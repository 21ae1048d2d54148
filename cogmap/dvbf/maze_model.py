"""DVBF-LM's model of a LiDAR maze as the runs and studies build it: the actuation noise of the
simulated robot and the model configuration sized to the maze."""

from __future__ import annotations

from cogmap.envs.maze_sim import ActuationNoise
from cogmap.genmodel.dvbf import DVBFConfig

#: the robot's actuation noise in every DVBF-LM run (heading std per step, translation fraction)
NOISE = ActuationNoise(rot_std=0.005, trans_frac=0.05)
#: hidden units of the emission network
HIDDEN = 64
#: transition std of x and y per step, metres (the heading's is the actuation noise's)
SIGMA_XY = 0.0005


def maze_model(maze, noise: ActuationNoise = NOISE) -> DVBFConfig:
    """The DVBF-LM configuration for ``maze``: its extent and map side, :data:`HIDDEN` units, and a
    transition noise of :data:`SIGMA_XY` in x and y and the actuation's heading std.

    Parameters
    ----------
    maze : cogmap.envs.maze.Maze
        The maze (its ``size`` and ``map_side``).
    noise : ActuationNoise, optional
        The robot's actuation noise; default :data:`NOISE`.

    Returns
    -------
    DVBFConfig
    """
    return DVBFConfig(extent=maze.size, map_side=maze.map_side, hidden=HIDDEN,
                      sigma_t=(SIGMA_XY, SIGMA_XY, noise.rot_std))

"""Simulated rooms: layouts, occupancy grids, pybullet robot and sensors, a grid world.

Importing this package registers the Gymnasium ids listed in `registry.ALL_IDS`; add your own
room with `register_layout(name, factory, env_id=...)`.
pybullet is only imported when a pybullet environment is created.
"""

from .geometry import Box, Cylinder
from .gridworld import GridWorld, GridWorldEnv
from .layouts import LAYOUTS, Layout, make_layout
from .maze import Maze, exploration_ratio, make_maze
from .occupancy import OccupancyGrid, layout_grid, rasterise
from .registry import ALL_IDS, LAYOUT_IDS, MAZE_ID, register_all, register_layout, unregister_layout
from .robot import MoveResult, OdometryNoise
from .sim import NavSim, SimConfig

register_all()

__all__ = [
    "ALL_IDS", "LAYOUTS", "LAYOUT_IDS", "MAZE_ID", "Maze", "exploration_ratio", "make_maze",
    "Box", "Cylinder", "GridWorld", "GridWorldEnv",
    "Layout", "MoveResult", "NavSim", "OccupancyGrid", "OdometryNoise", "SimConfig",
    "layout_grid", "make_layout", "rasterise", "register_all", "register_layout", "unregister_layout",
]

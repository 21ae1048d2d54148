"""Gymnasium ids for every layout; registered on `import cogmap.envs`."""

from __future__ import annotations

import gymnasium as gym

MAX_STEPS = 500

LAYOUT_IDS = {
    "cogmap/MiniWarehouse-v0": "mini_warehouse",
    "cogmap/SmallWarehouse-v0": "small_warehouse",
    "cogmap/LargeWarehouse-v0": "large_warehouse",
    "cogmap/House-v0": "house",
    "cogmap/Bedroom-v0": "bedroom",
    "cogmap/ParkingLot-v0": "parking_lot",
    "cogmap/AisleWarehouse-v0": "aisle_warehouse",
    "cogmap/RandomRooms-v0": "random_rooms",
    "cogmap/Building-v0": "building",  # an office floor; pass layout=make_layout("building", seed, kind=...)
}
GRID_ID = "cogmap/GridWorld-v0"
#: the DVBF-LM LiDAR maze (continuous controls; not part of ALL_IDS, whose envs share the discrete action set)
MAZE_ID = "cogmap/LidarMaze-v0"
MAZE_MAX_STEPS = 3000
ALL_IDS = (*LAYOUT_IDS, GRID_ID)
DRONE_ID = "cogmap/DroneField-v0"
DRONE_MAX_STEPS = 250


def register_all() -> None:
    """Register all ids (idempotent)."""
    for env_id, layout in LAYOUT_IDS.items():
        if env_id not in gym.registry:
            gym.register(env_id, entry_point="cogmap.envs.gym_env:NavEnv",
                         kwargs={"layout": layout}, max_episode_steps=MAX_STEPS)
    if GRID_ID not in gym.registry:
        gym.register(GRID_ID, entry_point="cogmap.envs.gridworld:GridWorldEnv",
                     max_episode_steps=MAX_STEPS)
    if DRONE_ID not in gym.registry:
        gym.register(DRONE_ID, entry_point="cogmap.envs.drone_gym:DroneFieldEnv",
                     max_episode_steps=DRONE_MAX_STEPS)
    if MAZE_ID not in gym.registry:
        gym.register(MAZE_ID, entry_point="cogmap.envs.maze_env:LidarMazeEnv",
                     max_episode_steps=MAZE_MAX_STEPS)

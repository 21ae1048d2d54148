"""Gymnasium ids for every layout; registered on `import cogmap.envs`.

:func:`register_layout` adds a user's room: ``make_layout(name)``, ``NavEnv(layout=name)``,
``gymnasium.make(env_id)`` and ``cogmap explore --env NAME`` (or ``--env ENV_ID``) then find it.
"""

from __future__ import annotations

from collections.abc import Callable

import gymnasium as gym

from cogmap.genmodel import contracts
from cogmap.genmodel.registry import check_entry, check_name

from .layouts import LAYOUTS, Layout

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
#: every id :func:`register_all` registers (users' rooms added by :func:`register_layout` are not in it)
BUILTIN_IDS = (*LAYOUT_IDS, GRID_ID, MAZE_ID, DRONE_ID)


# The environments' constructors, given to Gymnasium as callables: nothing is imported by a name
# string (the modules are imported here, when an environment is first made, since pybullet is slow
# to load).
def nav_env(**kwargs):
    """A room (:class:`cogmap.envs.gym_env.NavEnv`), as ``gymnasium.make`` builds it.

    Parameters
    ----------
    **kwargs
        ``NavEnv``'s arguments.

    Returns
    -------
    NavEnv
    """
    from .gym_env import NavEnv

    return NavEnv(**kwargs)


def grid_world_env(**kwargs):
    """The grid world (:class:`cogmap.envs.gridworld.GridWorldEnv`), as ``gymnasium.make`` builds it.

    Parameters
    ----------
    **kwargs
        ``GridWorldEnv``'s arguments.

    Returns
    -------
    GridWorldEnv
    """
    from .gridworld import GridWorldEnv

    return GridWorldEnv(**kwargs)


def drone_field_env(**kwargs):
    """The drone field (:class:`cogmap.envs.drone_gym.DroneFieldEnv`), as ``gymnasium.make`` builds it.

    Parameters
    ----------
    **kwargs
        ``DroneFieldEnv``'s arguments.

    Returns
    -------
    DroneFieldEnv
    """
    from .drone_gym import DroneFieldEnv

    return DroneFieldEnv(**kwargs)


def lidar_maze_env(**kwargs):
    """The LiDAR maze (:class:`cogmap.envs.maze_env.LidarMazeEnv`), as ``gymnasium.make`` builds it.

    Parameters
    ----------
    **kwargs
        ``LidarMazeEnv``'s arguments.

    Returns
    -------
    LidarMazeEnv
    """
    from .maze_env import LidarMazeEnv

    return LidarMazeEnv(**kwargs)


def register_all() -> None:
    """Register all ids (idempotent)."""
    for env_id, layout in LAYOUT_IDS.items():
        if env_id not in gym.registry:
            gym.register(env_id, entry_point=nav_env,
                         kwargs={"layout": layout}, max_episode_steps=MAX_STEPS)
    if GRID_ID not in gym.registry:
        gym.register(GRID_ID, entry_point=grid_world_env,
                     max_episode_steps=MAX_STEPS)
    if DRONE_ID not in gym.registry:
        gym.register(DRONE_ID, entry_point=drone_field_env,
                     max_episode_steps=DRONE_MAX_STEPS)
    if MAZE_ID not in gym.registry:
        gym.register(MAZE_ID, entry_point=lidar_maze_env,
                     max_episode_steps=MAZE_MAX_STEPS)


_BUILTIN_LAYOUTS = frozenset(LAYOUTS)


def register_layout(name: str, factory: Callable[..., Layout], *, env_id: str | None = None,
                    overwrite: bool = False, max_episode_steps: int = MAX_STEPS) -> None:
    """Register a room under ``name`` (and optionally the Gymnasium id ``env_id``).

    ``make_layout(name)``, ``NavEnv(layout=name)``, ``cogmap.explore.explore(name)`` and
    ``cogmap explore --env NAME`` then find it; with ``env_id`` also ``gymnasium.make(env_id)``
    and ``--env ENV_ID``.

    Parameters
    ----------
    name : str
        The room's name.
    factory : callable
        ``factory(seed: int = 0, **kwargs) -> Layout``; ``seed`` varies what the room
        randomises, if anything. Called once here with ``seed=0`` so a broken factory fails now.
    env_id : str, optional
        A Gymnasium id to register on :class:`~cogmap.envs.gym_env.NavEnv`.
    overwrite : bool
        Replace a room (and id) registered earlier under the same name.
    max_episode_steps : int
        Episode length of the Gymnasium id (default 500, as the built-in rooms).

    Raises
    ------
    ValueError
        Empty name, a built-in layout name or id, a name or id already taken without
        ``overwrite``, or a factory that does not return a :class:`Layout`.
    TypeError
        ``factory`` is not callable.
    """
    check_name("register_layout", name)
    check_entry("register_layout", "layout", name, factory, LAYOUTS, _BUILTIN_LAYOUTS, overwrite,
                expected="a callable factory(seed) -> Layout", same_again=False, protocol=contracts.LayoutFactory)
    if env_id is not None:
        if not isinstance(env_id, str) or not env_id:
            raise ValueError(f"register_layout('{name}'): env_id must be a non-empty string, got {env_id!r}")
        if env_id in LAYOUT_IDS and LAYOUT_IDS[env_id] in _BUILTIN_LAYOUTS:
            raise ValueError(f"register_layout: '{env_id}' is a built-in environment id")
        if env_id in gym.registry and not (overwrite and env_id in LAYOUT_IDS):
            raise ValueError(f"register_layout: the Gymnasium id '{env_id}' is taken"
                             + (" (pass overwrite=True)" if env_id in LAYOUT_IDS else ""))
    built = factory(0)
    if not isinstance(built, Layout):
        raise ValueError(f"register_layout('{name}'): the factory returned {type(built).__name__}, not a Layout")
    LAYOUTS[name] = factory
    if env_id is not None:
        LAYOUT_IDS[env_id] = name
        gym.registry.pop(env_id, None)  # overwrite: replace our own earlier registration quietly
        gym.register(env_id, entry_point=nav_env, kwargs={"layout": name},
                     max_episode_steps=max_episode_steps)


def unregister_layout(name: str) -> None:
    """Remove a registered room and its Gymnasium ids.

    Parameters
    ----------
    name : str
        A name given to :func:`register_layout`.

    Raises
    ------
    KeyError
        No registered room has that name (the message lists the registered ones).
    ValueError
        ``name`` is a built-in layout.
    """
    if name in _BUILTIN_LAYOUTS:
        raise ValueError(f"'{name}' is a built-in layout and cannot be removed")
    if name not in LAYOUTS:
        user = sorted(set(LAYOUTS) - _BUILTIN_LAYOUTS)
        raise KeyError(f"no registered layout named {name!r} (registered: {user})")
    del LAYOUTS[name]
    for env_id in [i for i, lay in LAYOUT_IDS.items() if lay == name]:
        del LAYOUT_IDS[env_id]
        gym.registry.pop(env_id, None)

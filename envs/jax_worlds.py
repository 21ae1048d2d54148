"""Pure JAX environments for the JAX backend: a generative process given by dense model arrays.

A world is the true ``A``, ``B`` and ``D`` of a task (a :class:`~cogmap.genmodel.jax_model.JaxModel`
used as the process, not as the agent's beliefs): ``reset`` draws the hidden state from ``D`` and
an observation from ``A``; ``step`` moves the state through ``B`` under the agent's controls and
draws the next observation. Both are pure functions of a ``jax.random`` key, so a whole episode
(agent and world) runs as one ``lax.scan`` (:func:`cogmap.jax_agent.rollout`) and thousands of
episodes in one ``vmap``.

    world = tmaze_world()                 # the T-maze of cogmap.genmodel.demo_models
    world = grid_world(side=10)            # an open grid with a noisy location sensor
    state, obs = reset(world, key)
    state, obs = step(world, state, action, key)
"""

from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from cogmap.genmodel import Factor, Modality, ModelSpec, compile
from cogmap.genmodel.demo_models import tmaze
from cogmap.genmodel.jax_model import JaxModel, Layout, to_jax


class World(NamedTuple):
    """A generative process: the layout and the true arrays of a task.

    Attributes
    ----------
    layout : Layout
        Static structure (hashable).
    arrays : JaxModel
        The true ``A``, ``B`` and ``D`` (``C`` and the counts are not used).
    """

    layout: Layout
    arrays: JaxModel


def _categorical(key, p):
    return jax.random.categorical(key, jnp.log(jnp.maximum(p, 1e-300)))


def observe(world: World, state, key) -> tuple:
    """One-hot observation vectors (one per modality) drawn from ``A`` at hidden ``state`` (``(F,)`` int)."""
    keys = jax.random.split(key, world.layout.num_modalities)
    out = []
    for m, deps in enumerate(world.layout.A_deps):
        p = world.arrays.A[m][(slice(None),) + tuple(state[f] for f in deps)]
        o = _categorical(keys[m], p)
        out.append(jax.nn.one_hot(o, world.layout.obs_capacity[m], dtype=world.arrays.A[m].dtype))
    return tuple(out)


def reset(world: World, key) -> tuple:
    """``(state, obs)``: the hidden state drawn from ``D`` and its observation."""
    k_s, k_o = jax.random.split(key)
    keys = jax.random.split(k_s, world.layout.num_factors)
    state = jnp.stack([_categorical(k, d) for k, d in zip(keys, world.arrays.D, strict=True)]).astype(jnp.int32)
    return state, observe(world, state, k_o)


def step(world: World, state, action, key) -> tuple:
    """``(state, obs)`` after controls ``action`` (``(F,)`` int): each factor moves through ``B``."""
    k_s, k_o = jax.random.split(key)
    keys = jax.random.split(k_s, world.layout.num_factors)
    nxt = jnp.stack([_categorical(keys[f], world.arrays.B[f][:, state[f], action[f]])
                     for f in range(world.layout.num_factors)]).astype(jnp.int32)
    return nxt, observe(world, nxt, k_o)


def tmaze_model(reward: float = 3.0, punishment: float = -6.0):
    """The T-maze of :func:`cogmap.genmodel.demo_models.tmaze` with preferences over the reward outcome.

    Parameters
    ----------
    reward, punishment : float, optional
        Log-preferences of the reward and the punishment outcomes, default 3 and -6.

    Returns
    -------
    Model
    """
    m = tmaze()
    m.C[1][:3] = [0.0, reward, punishment]
    return m


def _grid_moves(side: int) -> np.ndarray:
    """``(n, n, 5)`` transitions of a ``side x side`` grid: stay, +x, -x, +y, -y; walls keep you in place."""
    n = side * side
    B = np.zeros((n, n, 5))
    for s in range(n):
        x, y = s % side, s // side
        for u, (dx, dy) in enumerate(((0, 0), (1, 0), (-1, 0), (0, 1), (0, -1))):
            B[min(max(y + dy, 0), side - 1) * side + min(max(x + dx, 0), side - 1), s, u] = 1.0
    return B


def grid_model(side: int = 10, goal_preference: float = 4.0):
    """A ``side x side`` open grid: stay + 4 moves (walls keep you in place), a location sensor
    that is right 80 % of the time (else any cell), a preference for the far corner, start at 0.

    Parameters
    ----------
    side : int, optional
        Cells per side, default 10 (100 states).
    goal_preference : float, optional
        Log-preference of observing the far corner, default 4.

    Returns
    -------
    Model
    """
    n = side * side
    B = _grid_moves(side)
    C = np.zeros(n)
    C[n - 1] = goal_preference
    return compile(ModelSpec([Factor("cell", n, num_controls=5, stay=0)], [Modality("where", n, ("cell",))],
                             A={"where": 0.8 * np.eye(n) + 0.2 / n}, B={"cell": B}, C={"where": C},
                             D={"cell": np.eye(n)[0]}))


def landmark_grid_model(side: int = 5, goal_preference: float = 3.0, reliability: float = 0.4):
    """A ``side x side`` grid for fitting studies: the start is unknown within the first column,
    the location sensor is exact on the middle row (landmarks) and right with probability
    ``reliability`` elsewhere (else any cell), and the preference grows towards the far corner.

    Every choice then carries information about the agent: a utility-seeker walks down the
    preference gradient, an information-seeker heads for the landmarks, and the policy
    precision sets how consistently either does.

    Parameters
    ----------
    side : int, optional
        Cells per side, default 5 (25 states).
    goal_preference : float, optional
        Log-preference of the far corner over the start corner, default 3 (linear in the
        Manhattan distance between).
    reliability : float, optional
        Probability that the sensor names the true cell off the landmark row, in (0, 1]; default 0.4.

    Returns
    -------
    Model
    """
    if not 0.0 < reliability <= 1.0:
        raise ValueError(f"reliability must be in (0, 1], got {reliability}")
    n = side * side
    x, y = np.arange(n) % side, np.arange(n) // side
    landmark = y == side // 2
    A = np.where(landmark[None, :], np.eye(n), reliability * np.eye(n) + (1 - reliability) / n)
    C = goal_preference * (x + y) / (2 * (side - 1))
    D = np.where(x == 0, 1.0, 0.0)
    return compile(ModelSpec([Factor("cell", n, num_controls=5, stay=0)], [Modality("where", n, ("cell",))],
                             A={"where": A}, B={"cell": _grid_moves(side)}, C={"where": C},
                             D={"cell": D / D.sum()}))


def world_of(model) -> World:
    """The generative process of a dense compiled model (its own ``A``, ``B``, ``D``)."""
    return World(*to_jax(model))


def tmaze_world() -> World:
    """The T-maze as a JAX world (the context drawn from ``D`` at every reset)."""
    return world_of(tmaze_model())


def grid_world(side: int = 10) -> World:
    """The open grid of :func:`grid_model` as a JAX world."""
    return world_of(grid_model(side))


__all__ = ["World", "grid_model", "grid_world", "landmark_grid_model", "observe", "reset", "step", "tmaze_model",
           "tmaze_world", "world_of"]

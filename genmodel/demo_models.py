"""Small built-in models (T-maze, corridor, random) for ``cogmap compare-inference``, the
tutorials and quick experiments.

Each builder takes a numpy Generator and returns a compiled model.
"""

from __future__ import annotations

import numpy as np

from .compile import compile
from .model import Model
from .numerics import normalise
from .spec import Factor, Modality, ModelSpec


def tmaze(rng: np.random.Generator | None = None) -> Model:
    """Two factors (location x4 with 4 moves, context x2) and three modalities."""
    centre, left, right, cue = range(4)
    B_loc = np.zeros((4, 4, 4))
    for u in range(4):
        B_loc[u, :, u] = 1.0
    A_reward = np.zeros((3, 4, 2))
    A_reward[0, [centre, cue], :] = 1.0
    A_reward[1, left, 0] = A_reward[2, left, 1] = A_reward[1, right, 1] = A_reward[2, right, 0] = 0.9
    A_reward[2, left, 0] = A_reward[1, left, 1] = A_reward[2, right, 1] = A_reward[1, right, 0] = 0.1
    A_cue = np.full((2, 4, 2), 0.5)
    A_cue[:, cue, :] = [[0.95, 0.05], [0.05, 0.95]]
    return compile(ModelSpec(
        factors=[Factor("location", 4, num_controls=4), Factor("context", 2)],
        modalities=[Modality("where", 4, ("location",)), Modality("reward", 3, ("location", "context")),
                    Modality("cue", 2, ("location", "context"))],
        A={"where": 0.9 * np.eye(4) + 0.025, "reward": A_reward, "cue": A_cue},
        B={"location": 0.9 * B_loc + 0.025, "context": np.eye(2)[:, :, None]},
        D={"location": np.eye(4)[centre]},
    ))


def corridor(rng: np.random.Generator | None = None, n: int = 8) -> Model:
    """A corridor of ``n`` places with aliased colours and slippery moves (stay, east, west)."""
    rng = rng or np.random.default_rng(0)
    B = np.zeros((n, n, 3))
    B[:, :, 0] = np.eye(n)
    for s in range(n):
        B[min(s + 1, n - 1), s, 1] += 0.8
        B[s, s, 1] += 0.2
        B[max(s - 1, 0), s, 2] += 0.8
        B[s, s, 2] += 0.2
    colours = rng.integers(0, 3, size=n)
    A = np.full((3, n), 0.05)
    A[colours, np.arange(n)] = 0.9
    return compile(ModelSpec(
        factors=[Factor("place", n, num_controls=3, stay=0)],
        modalities=[Modality("colour", 3, ("place",))],
        A={"colour": A},
        B={"place": B},
    ))


def random_model(rng: np.random.Generator | None = None) -> Model:
    """Two factors (3 and 4 states, 2 controls each), two modalities on different factors."""
    rng = rng or np.random.default_rng(0)
    return compile(ModelSpec(
        factors=[Factor("a", 3, num_controls=2), Factor("b", 4, num_controls=2)],
        modalities=[Modality("x", 4, ("a",)), Modality("y", 3, ("a", "b"))],
        A={"x": normalise(rng.random((4, 3)) ** 3), "y": normalise(rng.random((3, 3, 4)) ** 3)},
        B={"a": normalise(rng.random((3, 3, 2)) ** 4), "b": normalise(rng.random((4, 4, 2)) ** 4)},
    ))


ROOM_MOVES = ((0, 0), (1, 0), (-1, 0), (0, 1), (0, -1))  # stay, east, west, north, south


def aliased_room(side: int = 4, views: int = 6, noise: float = 0.06, seed: int = 7):
    """The arrays of a ``side x side`` room where places share ``views`` observations (aliased):
    ``(A, B, label)`` with ``A`` (views, places) emitting a place's view with probability
    ``1 - noise`` (the rest spread evenly), ``B`` (places, places, 5) the deterministic moves of
    ``ROOM_MOVES`` (a wall keeps you in place) and ``label`` each place's view."""
    n = side * side
    B = np.zeros((n, n, len(ROOM_MOVES)))
    for s in range(n):
        x, y = s % side, s // side
        for u, (dx, dy) in enumerate(ROOM_MOVES):
            B[min(max(y + dy, 0), side - 1) * side + min(max(x + dx, 0), side - 1), s, u] = 1.0
    label = np.random.default_rng(seed).permutation(np.arange(n) % views)
    A = np.full((views, n), noise / (views - 1))
    A[label, np.arange(n)] = 1 - noise
    return A, B, label


def room_model(A, B, conc=None) -> Model:
    """The one-factor room model of ``(A, B)`` (uniform ``D``), or with ``conc`` given a learner of
    ``B``: ``B`` uniform and prior counts ``conc`` on every entry.

    Parameters
    ----------
    A : numpy.ndarray
        ``(views, places)`` likelihood (e.g. from :func:`aliased_room`).
    B : numpy.ndarray
        ``(places, places, controls)`` transitions.
    conc : float, optional
        Prior count per entry of a learned ``B``; None keeps ``B`` as given.

    Returns
    -------
    Model
    """
    n, U = B.shape[1], B.shape[2]
    spec = ModelSpec([Factor("place", n, num_controls=U)], [Modality("view", A.shape[0], ("place",))],
                     A={"view": A}, B={"place": B if conc is None else np.full((n, n, U), 1 / n)},
                     D={"place": np.full(n, 1 / n)})
    if conc is not None:
        spec.pB["place"] = np.full((n, n, U), conc)
    return compile(spec)


def room_walk(A, B, steps: int, seed: int):
    """A seeded random walk of ``steps`` observations in a room with deterministic moves ``B``.

    Parameters
    ----------
    A, B : numpy.ndarray
        As for :func:`room_model`.
    steps : int
        Observations (one more than actions).
    seed : int
        Seed of the start, the moves and the views.

    Returns
    -------
    obs : list of list of int
        One ``[view]`` per step.
    acts : list of int
        The ``steps - 1`` moves.
    places : numpy.ndarray
        ``(steps,)`` int true places.
    """
    rng = np.random.default_rng(seed)
    s, obs, acts, places = int(rng.integers(B.shape[0])), [], [], []
    for t in range(steps):
        if t:
            acts.append(int(rng.integers(B.shape[2])))
            s = int(np.argmax(B[:, s, acts[-1]]))
        places.append(s)
        obs.append([int(rng.choice(A.shape[0], p=A[:, s]))])
    return obs, acts, np.array(places)


MODELS = {"tmaze": tmaze, "corridor": corridor, "random": random_model}

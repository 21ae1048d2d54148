"""One decision from a compiled cogmap.genmodel Model (the agent-loop entry point)."""

from __future__ import annotations

import numpy as np
import pytest

from cogmap.genmodel import (
    Factor,
    InductiveSpec,
    Modality,
    ModelSpec,
    PoseSpec,
    SparseB,
    compile,
)
from cogmap.planning import MCTSConfig, decide, from_model


def _corridor_model(n=6, goal=None):
    succ = np.zeros((n, 3, 2), dtype=np.int64)
    prob = np.zeros((n, 3, 2))
    for s in range(n):
        for u, t in ((0, min(s + 1, n - 1)), (1, max(s - 1, 0)), (2, s)):
            succ[s, u] = (t, s)
            prob[s, u] = (1.0, 0.0) if t == s else (0.9, 0.1)
    A = np.full((n, n), 0.1 / (n - 1))
    np.fill_diagonal(A, 0.9)
    A[:, n - 2 :] = 1.0 / n  # the last two states are unvisited: uniform columns
    C_states = np.zeros(n)
    if goal is not None:
        C_states[goal] = 1.0
    spec = ModelSpec(
        factors=[Factor("loc", n, num_controls=3, stay=2)],
        modalities=[Modality("view", n, ("loc",))],
        A={"view": A},
        B={"loc": SparseB(succ, prob)},
        pA={"view": np.where(A == 1.0 / n, 0.05, A * 20 + 0.1)},  # barely counted when unvisited
        C_states={"loc": C_states},
        pose=PoseSpec("loc", np.stack([np.arange(n, dtype=float), np.zeros(n)], 1), [0.0, np.pi]),
        inductive=InductiveSpec(threshold=0.5, depth=10, weight=1.0),
        collision_preference=-8.0,
    )
    return compile(spec)


def test_decide_explore_goal_and_obstacles_from_model():
    model = _corridor_model()
    qs = np.eye(6)[2]
    d = decide(model, qs, np.zeros(3, bool), "explore", rng=0)
    assert d.action == 0  # toward the unvisited (uncertain) end of the corridor
    d = decide(model, qs, np.array([True, False, False]), "explore", rng=0)
    assert d.action != 0  # the obstacle flag wins over curiosity
    model = _corridor_model(goal=0)
    d = decide(model, qs, None, "goal", rng=0)
    assert d.action == 1
    d = decide(model, qs, None, "goal", target_pose=(5.0, 0.0), goal_states=[5], rng=0)
    assert d.action == 0


def test_from_model_derives_goal_and_settings():
    model = _corridor_model(goal=4)
    arrays = from_model(model)
    assert arrays.goal_states.tolist() == [4]
    assert arrays.collision_pref == -8.0 and arrays.inductive_depth == 10
    assert arrays.stay == (2,)
    assert from_model(_corridor_model()).goal_states.size == 0


def test_decide_rejects_unknown_mode():
    with pytest.raises(ValueError, match="unknown planning mode"):
        decide(_corridor_model(), np.eye(6)[0], mode="wander", config=MCTSConfig(simulations=2))

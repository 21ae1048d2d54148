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


def test_planning_takes_a_compiled_model_directly():
    from cogmap.genmodel import Factor, Modality, ModelSpec, compile
    from cogmap.planning import efe
    from cogmap.planning.arrays import from_model
    from cogmap.planning.policies import evaluate_policies, infer_policies

    rng = np.random.default_rng(0)
    A = rng.dirichlet(np.ones(3), size=4).T
    B = np.stack([rng.dirichlet(np.ones(4), size=4).T for _ in range(2)], axis=2)
    model = compile(ModelSpec(factors=[Factor("s", 4, num_controls=2)], modalities=[Modality("o", 3, ("s",))],
                              A={"o": A}, B={"s": B}, C={"o": np.array([1.0, 0.0, -1.0])}))
    qs = [np.full(4, 0.25)]
    obj = efe.pymdp_like()
    first, q, G, policies = infer_policies(model, qs, obj, length=2, gamma=1.0, rng=np.random.default_rng(0))
    np.testing.assert_allclose(G, evaluate_policies(from_model(model), qs, policies, obj), atol=1e-14)
    with pytest.raises(TypeError, match="compiled Model or PlanningArrays"):
        infer_policies({"A": A}, qs, obj)


def test_planning_calls_limit_blas_threads_and_the_limit_is_overridable(monkeypatch):
    from planning_builders import random_dense
    from threadpoolctl import threadpool_info

    from cogmap.planning import efe, threads
    from cogmap.planning.policies import evaluate_policies

    seen = []

    def spy(ctx):  # an EFE term that records the BLAS threads while planning runs
        seen.append(min(i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"))
        return np.zeros(ctx.num_candidates)

    arrays, _ = random_dense(np.random.default_rng(1))
    obj = efe.objective([(spy, 1.0)])
    policies = np.zeros((1, 1, 1), dtype=int)
    outside = min(i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas")
    evaluate_policies(arrays, [np.full(4, 0.25)], policies, obj)
    assert seen[-1] == 1
    monkeypatch.setenv("COGMAP_PLANNING_THREADS", "0")
    evaluate_policies(arrays, [np.full(4, 0.25)], policies, obj)
    assert seen[-1] == outside
    threads.set_threads(1)  # the explicit setting wins over the environment
    try:
        evaluate_policies(arrays, [np.full(4, 0.25)], policies, obj)
        assert seen[-1] == 1
    finally:
        threads.set_threads(None)
    assert min(i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas") == outside
    monkeypatch.setenv("COGMAP_PLANNING_THREADS", "many")
    with pytest.raises(ValueError, match="non-negative integer"):
        threads.threads()
    with pytest.raises(ValueError, match="non-negative integer"):
        threads.set_threads(-1)

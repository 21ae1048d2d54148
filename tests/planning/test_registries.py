"""EFE terms and planners by name: registration, their clear errors, and their use downstream."""

from __future__ import annotations

import numpy as np
import pytest

from cogmap import loop
from cogmap.genmodel import Factor, Modality, ModelSpec, compile
from cogmap.genmodel.demo_models import corridor
from cogmap.planning import (
    Plan,
    available_planners,
    available_terms,
    decide,
    efe,
    get_planner,
    objective,
    register_planner,
    register_term,
    unregister_planner,
    unregister_term,
)
from cogmap.planning.arrays import from_model, prepare
from cogmap.planning.context import DenseStep


@pytest.fixture
def term_name():
    names = []
    yield names
    for n in names:
        unregister_term(n)


UNREGISTER = unregister_planner  # what the suite's ``registered`` fixture removes with


def _certain(model, s: int) -> list[np.ndarray]:
    q = np.zeros(model.num_states[0])
    q[s] = 1.0
    return [q]


# -- terms ------------------------------------------------------------------------------------
def test_register_term_errors(term_name):
    with pytest.raises(ValueError, match="non-empty string"):
        register_term("", lambda ctx: 0)
    with pytest.raises(TypeError, match="expected a callable"):
        register_term("not_callable", 3.0)
    with pytest.raises(ValueError, match="built-in EFE term"):
        register_term("collision", lambda ctx: 0)
    register_term("toy_term", efe.collision)
    term_name.append("toy_term")
    register_term("toy_term", efe.collision)  # the same term again: no error
    with pytest.raises(ValueError, match="exists.*overwrite=True"):
        register_term("toy_term", efe.inductive)
    register_term("toy_term", efe.inductive, overwrite=True)
    assert objective({"toy_term": 1.0}).terms == ((efe.inductive, 1.0),)
    with pytest.raises(KeyError, match="unknown EFE term 'nope'.*toy_term"):
        objective({"nope": 1.0})
    with pytest.raises(KeyError, match="no registered EFE term named 'nope'"):
        unregister_term("nope")
    assert "toy_term" in available_terms() and "collision" in available_terms()


def test_a_registered_term_steers_the_planners_by_name(term_name):
    """A term preferring the east end of the corridor makes MCTS and the loop go east where the
    plain objective (pymdp's: utility + state information gain) goes west."""
    model = corridor(np.random.default_rng(0), n=6)
    last = model.num_states[0] - 1

    def at_the_end(ctx):
        return ctx.qs[0][:, last] * 10.0

    register_term("at_the_end", at_the_end)
    term_name.append("at_the_end")
    obj = objective({"state_info_gain": 1.0, "at_the_end": 1.0})
    qs = _certain(model, 1)
    assert np.atleast_1d(decide(model, qs, None, efe.pymdp_like(), rng=0).action).tolist() == [2]  # west
    assert np.atleast_1d(decide(model, qs, None, obj, rng=0).action).tolist() == [1]  # east
    _, plain = loop.step(loop.init(model, policy_len=2, sample=False), [0])
    _, steered = loop.step(loop.init(model, objective=obj, policy_len=2, sample=False), [0])
    assert (plain.action, steered.action) == ((2,), (1,))
    # and it is the term's value: G changes by exactly -10 * P(at the end) per candidate
    arrays = prepare(from_model(model), local=False)
    ctx = DenseStep(arrays, [np.tile(qs[0], (3, 1))], np.array([[0], [1], [2]]))
    base = objective({"state_info_gain": 1.0})(ctx)
    np.testing.assert_allclose(obj(ctx) - base, -10.0 * ctx.qs[0][:, last])


def test_a_user_term_sees_the_novelty_arrays_in_decide(term_name):
    """decide prepares what built-in terms read only when they are used; a user term may read
    any context attribute, so with one in the objective everything is prepared."""
    base = corridor(np.random.default_rng(0), n=4)
    model = compile(ModelSpec(
        factors=[Factor("s", 4, num_controls=3)], modalities=[Modality("o", base.num_obs[0], ("s",))],
        A={"o": base.live_A(0)}, B={"s": base.live_B(0)}, pA={"o": 2 * base.live_A(0) + 0.1},
    ))
    seen = []

    def novelty_reader(ctx):
        seen.append(ctx.a_novelty[0])
        return np.zeros(ctx.num_candidates)

    register_term("novelty_reader", novelty_reader)
    term_name.append("novelty_reader")
    decide(model, _certain(model, 1), None, objective({"novelty_reader": 1.0}), rng=0)
    assert seen and all(v is not None and np.all(np.isfinite(v)) for v in seen)
    assert max(float(np.max(v)) for v in seen) > 0


def test_epistemic_flag_decides_what_split_counts_once(term_name):
    model = corridor(np.random.default_rng(0), n=4)
    arrays = prepare(from_model(model), local=False)
    ctx = DenseStep(arrays, [np.tile(_certain(model, 1)[0], (3, 1))], np.array([[0], [1], [2]]))

    def bonus(ctx):
        return np.arange(ctx.num_candidates, dtype=float)

    register_term("bonus_plain", bonus)
    register_term("bonus_info", lambda c: bonus(c), epistemic=True)
    term_name.extend(["bonus_plain", "bonus_info"])
    g, g_known = objective({"bonus_plain": 1.0}).split(ctx)
    np.testing.assert_allclose(g_known, g)
    g, g_known = objective({"bonus_info": 1.0}).split(ctx)
    np.testing.assert_allclose(g, -np.arange(3.0))
    np.testing.assert_allclose(g_known, 0.0)


# -- planners ---------------------------------------------------------------------------------
def test_register_planner_errors(registered):
    def west(model, qs, objective, settings):
        return Plan((2,), np.zeros(1))

    with pytest.raises(ValueError, match="non-empty string"):
        register_planner("", west)
    with pytest.raises(TypeError, match="expected a callable"):
        register_planner("west", "not a function")
    with pytest.raises(ValueError, match="built-in planner"):
        register_planner("mcts", west)
    register_planner("west", west)
    registered.append("west")
    with pytest.raises(ValueError, match="exists.*overwrite=True"):
        register_planner("west", lambda *a: None)
    assert get_planner("west") is west
    with pytest.raises(KeyError, match="unknown planner 'nope'.*enumerate, mcts, sophisticated, west"):
        get_planner("nope")
    with pytest.raises(ValueError, match="unknown planner 'nope'.*west"):
        loop.init(corridor(), planner="nope")
    with pytest.raises(ValueError, match="built-in planner"):
        unregister_planner("enumerate")
    with pytest.raises(KeyError, match="no planner named 'nope'"):
        unregister_planner("nope")
    assert set(available_planners()) >= {"enumerate", "mcts", "west"}


def test_the_loop_runs_a_registered_planner_with_its_settings(registered):
    calls = []

    @register_planner("always_west")
    def always_west(model, qs, objective, settings):
        calls.append((len(qs), settings.policy_len, settings.gamma, settings.rng is not None))
        return Plan((2,), np.array([0.5]))

    registered.append("always_west")
    state = loop.init(corridor(), planner="always_west", policy_len=3, gamma=4.0)
    state, info = loop.step(state, [0])
    assert info.action == (2,) and info.q_pi is None and info.G.tolist() == [0.5]
    assert calls == [(1, 3, 4.0, True)]
    # the next prior is the posterior pushed through B under the planner's control
    np.testing.assert_allclose(state.prior[0], state.model.predict(0, info.qs[0], 2))

    register_planner("two_controls", lambda m, qs, o, s: Plan((1, 1), np.zeros(1)))
    registered.append("two_controls")
    with pytest.raises(ValueError, match="returned 2 control"):
        loop.step(loop.init(corridor(), planner="two_controls"), [0])


def test_builtin_planners_by_name_match_the_direct_calls():
    from cogmap.planning.planners import PlanSettings
    from cogmap.planning.policies import infer_policies

    model = corridor(np.random.default_rng(1), n=5)
    qs = _certain(model, 2)
    plan = get_planner("enumerate")(model, qs, efe.pymdp_like(), PlanSettings(policy_len=2, sample=False))
    a, q_pi, G, _ = infer_policies(model, qs, efe.pymdp_like(), length=2)
    assert plan.action == tuple(int(x) for x in a)
    np.testing.assert_allclose(plan.q_pi, q_pi)
    np.testing.assert_allclose(plan.G, G)


def test_a_user_term_indexing_by_U_agrees_between_the_local_and_dense_contexts(term_name):
    """The Extending page's contract: in a LocalStep ``qs[0]`` covers the states ``ctx.U``; a term
    that indexes its per-state array with ``ctx.U`` there gives the DenseStep's values."""
    from cogmap.planning.context import LocalStep
    from cogmap.planning.testing import graph_arrays

    from .planning_builders import chain

    G, poses = chain(8)
    arrays = graph_arrays(G, poses, p_move=0.8)
    bonus = 1.0 / np.sqrt(1.0 + np.arange(8.0) ** 2)

    def by_state(ctx):
        return ctx.qs[0] @ (bonus[ctx.U] if isinstance(ctx, LocalStep) else bonus)

    register_term("by_state", by_state)
    term_name.append("by_state")
    obj = objective({"by_state": 1.0})
    prior = np.zeros(8)
    prior[[3, 4]] = [0.3, 0.7]
    actions = np.arange(arrays.num_controls[0])
    local = LocalStep(prepare(arrays, local=True), np.array([3, 4]), np.array([0.3, 0.7]), actions)
    dense = DenseStep(prepare(arrays, local=False), [np.tile(prior, (actions.size, 1))], actions[:, None])
    np.testing.assert_allclose(obj(local), obj(dense), atol=1e-12)
    assert np.ptp(obj(dense)) > 1e-3  # the moves differ, so the check has teeth

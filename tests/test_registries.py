"""One conformance test over every registry: each registered entry meets its contract
(:mod:`cogmap.genmodel.contracts`) and runs once on a tiny case; registering something that does
not conform is refused with the contract named."""

from __future__ import annotations

import numpy as np
import pytest

from cogmap import agents, inference, loop
from cogmap.genmodel import contracts
from cogmap.genmodel.demo_models import corridor, tmaze
from cogmap.planning import efe
from cogmap.planning.planners import available_planners, get_planner, register_planner


# -- inference schemes --------------------------------------------------------------------------------
def _particle_model():
    import jax
    import jax.numpy as jnp

    def transition(key, z, u):
        return z + u + 0.1 * jax.random.normal(key, z.shape)

    def log_likelihood(z, x):
        return -0.5 * jnp.sum((z - x) ** 2, axis=-1)  # particles (K, D) -> (K,)

    return inference.ParticleModel(transition, log_likelihood)


def _tiny_case(name: str):
    """The first tiny model the scheme accepts, its prior and a short sequence."""
    from cogmap.genmodel.drone_beliefs import KernelBeliefModel
    from cogmap.inference.compare import generate_sequence

    for model in (tmaze(), corridor(np.random.default_rng(0))):
        if inference.accepts(name, model):
            seq = generate_sequence(model, 2, seed=0)
            return model, [model.live_D(f) for f in range(len(model.factors))], seq.observations, seq.actions
    if inference.accepts(name, KernelBeliefModel()):
        obs = {"distance": 40.0, "azimuth": 0.7, "elevation": -0.2, "suitability": 0.8, "density": 0.05}
        return KernelBeliefModel(), None, [obs], None
    model = _particle_model()
    assert inference.accepts(name, model), f"no tiny case for scheme {name!r}"
    return model, (np.zeros(1), np.ones(1)), [np.zeros(1), np.ones(1)], [np.ones(1)]


@pytest.mark.parametrize("name", inference.available())
def test_every_scheme_conforms_and_infers_on_a_tiny_model(name):
    fn = inference.get(name)
    assert contracts.conformance_errors(fn, contracts.InferenceScheme) == []
    model, prior, obs, acts = _tiny_case(name)
    options = {"num_particles": 64} if name == "particle_filter" else {}
    post, info = fn(model, prior, obs, acts, **options)
    assert np.isfinite(info.free_energy)
    assert name in inference.accepting(model)


def test_a_scheme_with_the_wrong_call_or_an_unknown_accepts_is_refused():
    with pytest.raises(TypeError, match="does not meet the InferenceScheme contract: it cannot be called as"):
        inference.register("two_args", lambda model, prior: None)
    with pytest.raises(TypeError, match="accepts must be a model type"):
        inference.register("bad_accepts", lambda m, p, o, a=None: None, accepts=3)
    assert "two_args" not in inference.available() and "bad_accepts" not in inference.available()


def test_an_accepts_test_that_fails_on_another_kind_of_model_does_not_accept_it():
    inference.register("one_factor_only", lambda m, p, o, a=None: None, accepts=lambda m: len(m.factors) == 1)
    try:
        assert "one_factor_only" in inference.accepting(corridor(np.random.default_rng(0)))
        assert "one_factor_only" not in inference.accepting(tmaze())  # two factors
        assert not inference.accepts("one_factor_only", _particle_model())  # no .factors: not accepted
    finally:
        inference.unregister("one_factor_only")


# -- planners -----------------------------------------------------------------------------------------
def _drone_scene():
    from cogmap.planning.drone_planner import DronePlannerConfig, DroneScene

    voxels = np.array([[5.0, 0.5, 2.0], [5.0, -0.5, 2.0]])
    return DroneScene(np.array([0.0, 0.0, 2.0]), np.array([20.0, 0.0, 2.0]), voxels, 5.0, 0.02, 0.8, 20.0,
                      np.zeros((0, 3)), DronePlannerConfig())


@pytest.mark.parametrize("name", available_planners())
def test_every_planner_conforms_and_plans_a_step(name):
    from cogmap.genmodel.drone_beliefs import KernelBeliefModel
    from cogmap.planning.planners import PlanSettings, accepting_planners

    assert contracts.conformance_errors(get_planner(name), contracts.Planner) == []
    cases = [m for m in (tmaze(), _drone_scene()) if name in accepting_planners(m)]
    assert len(cases) == 1  # every planner takes exactly one of the two tiny cases
    if isinstance(cases[0], tuple) and hasattr(cases[0], "voxels"):  # a drone scene: kernel beliefs
        beliefs = inference.get("kernel")(KernelBeliefModel(), None, [{"distance": 20.0, "azimuth": 0.0,
                                                                       "elevation": 0.0, "suitability": 0.8,
                                                                       "density": 0.02}])[0]
        plan = get_planner(name)(cases[0], beliefs, None, PlanSettings(policy_len=2, rng=np.random.default_rng(0)))
        assert np.asarray(plan.action).shape == (3,) and np.all(np.isfinite(plan.G))
        return
    state = loop.init(cases[0], planner=name, seed=0)
    state, info = loop.step(state, [0, 0, 0])
    assert len(info.action) == 2 and np.all(np.isfinite(np.asarray(info.G, float)))


def test_a_planner_that_cannot_take_the_planners_arguments_is_refused():
    with pytest.raises(TypeError, match="does not meet the Planner contract"):
        register_planner("one_arg", lambda model: None)
    assert "one_arg" not in available_planners()


# -- EFE terms ----------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", sorted(efe.ALL_TERMS))
def test_every_efe_term_conforms_and_scores_the_candidates_of_a_step(name):
    term = efe.ALL_TERMS[name]
    assert contracts.conformance_errors(term, contracts.EFETerm) == []
    state = loop.init(tmaze(), objective=efe.objective({name: 1.0}), sample=False, seed=0)
    _, info = loop.step(state, [0, 0, 0])
    assert np.asarray(info.G).shape[0] >= 1 and np.all(np.isfinite(np.asarray(info.G, float)))


def test_a_term_that_takes_no_context_is_refused():
    with pytest.raises(TypeError, match="does not meet the EFETerm contract"):
        efe.register_term("no_ctx", lambda: 0.0)


# -- factor representations ---------------------------------------------------------------------------
def test_dense_and_sparse_likelihoods_and_transitions_meet_one_contract_each():
    from cogmap.genmodel.likelihood import SparseLikelihood
    from cogmap.genmodel.transitions import SparseTransitions

    model = corridor(np.random.default_rng(0))
    dense_a, dense_b = model.A[0], model.B[0]
    sparse_b = SparseTransitions.from_dense(dense_b.prob, counts=dense_b.counts)
    sparse_a = SparseLikelihood(3, 0, capacity=4)
    for rep in (dense_a, sparse_a):
        assert type(rep).__name__ in ("DenseLikelihood", "SparseLikelihood")
        assert contracts.conformance_errors(rep, contracts.LikelihoodRepresentation) == [], type(rep)
    for rep in (dense_b, sparse_b):
        assert contracts.conformance_errors(rep, contracts.TransitionRepresentation) == [], type(rep)
    n = model.num_states[0]
    for u in range(dense_b.num_controls):  # the two representations answer alike
        np.testing.assert_allclose(sparse_b.to_dense(n)[:, :, u], dense_b.to_dense(n)[:, :, u], atol=1e-12)


# -- rooms ----------------------------------------------------------------------------------------------
def test_every_room_conforms_and_builds():
    from cogmap.envs.layouts import LAYOUTS, Layout

    for name, factory in LAYOUTS.items():
        assert contracts.conformance_errors(factory, contracts.LayoutFactory) == [], name
        layout = factory(0)
        assert isinstance(layout, Layout) and layout.shapes and layout.starts, name


def test_a_room_factory_without_a_seed_is_refused():
    from cogmap.envs import register_layout

    with pytest.raises(TypeError, match="does not meet the LayoutFactory contract"):
        register_layout("no_seed", lambda: None)


# -- observation encoders -----------------------------------------------------------------------------
def test_every_encoder_conforms_and_encodes_a_view():
    pytest.importorskip("cv2")
    from cogmap.agent.config import AgentConfig
    from cogmap.agent.encoder import available_encoders, make_encoder

    image = np.random.default_rng(0).integers(0, 255, (32, 128, 3), dtype=np.uint8)
    for name in available_encoders():
        enc = make_encoder(name, AgentConfig())
        assert contracts.conformance_errors(enc, contracts.Encoder) == [], name
        assert enc(image) == (0, True) and enc(image) == (0, False) and enc.match(image)[0] == 0


# -- agents ---------------------------------------------------------------------------------------------
def test_every_agent_conforms_to_init_and_step():
    assert set(agents.agents()) >= {"loop", "aimapp", "drone"}
    for name in agents.agents():
        assert contracts.conformance_errors(agents.get_agent(name), contracts.Agent) == [], name
    with pytest.raises(TypeError, match="does not meet the Agent contract: init cannot be called as"):
        agents.register_agent("bad", init=lambda model: None, step=lambda s, o: (s, None))
    with pytest.raises(ValueError, match="built-in agent"):
        agents.register_agent("loop", init=lambda m, c, k: None, step=lambda s, o: (s, None))


def test_the_loop_agent_is_cogmap_loop():
    agent = agents.get_agent("loop")
    a = agent.init(tmaze(), {"policy_len": 2, "sample": False}, 3)
    b = loop.init(tmaze(), policy_len=2, sample=False, seed=3)
    for obs in ([0, 0, 0], [1, 1, 0]):
        a, info_a = agent.step(a, obs)
        b, info_b = loop.step(b, obs)
        assert info_a.action == info_b.action
        np.testing.assert_allclose(info_a.q_pi, info_b.q_pi)


def test_the_aimapp_agent_steps_as_the_exploration_does():
    pytest.importorskip("pybullet")
    from cogmap.agent.aimapp import AIMAPPAgent
    from cogmap.agent.policy import sense
    from cogmap.explore import default_config, make_sim

    cfg = default_config("mini_warehouse")
    runs = []
    for via_registry in (True, False):
        sim = make_sim("mini_warehouse", cfg, 0)
        try:
            agent = agents.get_agent("aimapp")
            state = agent.init(None, cfg, 0) if via_registry else AIMAPPAgent(cfg, seed=0)
            moved, out = None, []
            for _ in range(4):
                sensed = sense(sim, moved, cfg)
                if via_registry:
                    state, d = agent.step(state, sensed)
                else:
                    d = state.step(sensed)
                out.append((d.state, d.action, d.mode))
                result = sim.stay() if d.action == cfg.stay else sim.move_to(d.waypoint, frame="odom")
                moved = bool(result.success)
            runs.append(out)
        finally:
            sim.close()
    assert runs[0] == runs[1]


def test_the_drone_agent_decides_as_the_episode_does():
    pytest.importorskip("pybullet")
    from cogmap.drone.agent import DroneAgent
    from cogmap.drone.run import episode_target
    from cogmap.envs.drone_sim import DroneSim

    sim = DroneSim(0)
    try:
        target = episode_target(sim, 0, 0)
        start = sim.reset()
        direct = DroneAgent(seed=0)
        scan = sim.scan()
        direct.reset(target, start)
        direct.observe(scan, start)
        expected = direct.decide(start, target)
        agent = agents.get_agent("drone")
        state = agent.init(None, None, 0)
        state.reset(target, start)
        state, got = agent.step(state, agents.DroneObservation(scan, start, target))
        np.testing.assert_array_equal(got.waypoint, expected.waypoint)
        assert got.speed == expected.speed
        with pytest.raises(ValueError, match="pass model=None"):
            agent.init(tmaze(), None, 0)
    finally:
        sim.close()


# -- studies --------------------------------------------------------------------------------------------
def test_every_study_conforms_plans_and_keys_its_runs():
    from cogmap.study import get_study, run_specs, studies, study_plan

    for name in studies():
        entry = get_study(name)
        assert contracts.conformance_errors(entry, contracts.Study) == [], name
        specs = run_specs(study_plan(name, "tiny"))
        assert specs and all(s["study"] == name for s in specs), name
        assert len({s["key"] for s in specs}) == len(specs), name


@pytest.mark.parametrize("name", ["exploration", "goals", "drift", "obstacle", "scaling", "drone"])
def test_a_tiny_run_of_each_fast_study_goes_through_the_registry(name):
    """The DVBF-LM studies' runs take seconds each: tests/dvbf/test_*study*.py run them."""
    pytest.importorskip("pybullet")
    from cogmap.study.registry import execute, run_specs, study_plan

    spec = run_specs(study_plan(name, "tiny", seeds=[0]))[0]
    record = execute(spec)
    assert record["key"] == spec["key"] and isinstance(record["result"], dict) and record["result"]


def test_a_study_missing_a_function_is_refused():
    from cogmap.study import register_study

    with pytest.raises(TypeError, match="does not meet the Study contract: specs cannot be called as"):
        register_study("half", plan=lambda scale, seeds=None, methods=None, envs=None: {}, specs=lambda: [],
                       run=lambda spec: {}, report=lambda d, p, r: "")

"""AIMAPP localises with any registered inference scheme that accepts its model
(``AgentConfig(scheme=...)``, ``cogmap explore --scheme``). Its model has one hidden factor and
each step is one observation, so every exact or variational scheme reaches the exact posterior:
the runs must agree with the paper's filter step by step."""

import json
from dataclasses import replace

import numpy as np
import pytest

from cogmap import inference
from cogmap.agent.aimapp import AIMAPPAgent, initial_model
from cogmap.cli import main
from cogmap.explore import default_config, make_sim, run_agent

pytest.importorskip("pybullet", reason="the sim extra is needed for pybullet runs")

STEPS = 12


def _run(scheme: str):
    cfg = replace(default_config("mini_warehouse"), scheme=scheme)
    sim = make_sim("mini_warehouse", cfg, 0)
    try:
        agent = AIMAPPAgent(cfg, seed=0)
        decisions, beliefs = [], []

        def record(d):
            decisions.append((d.state, d.action, d.mode))
            beliefs.append(agent.q.copy())

        run_agent(sim, agent, STEPS, progress=False, on_step=record)
        return decisions, beliefs, agent
    finally:
        sim.close()


def test_the_schemes_that_accept_aimapps_model_are_the_discrete_ones():
    model = initial_model(default_config("mini_warehouse"), np.zeros(2))
    assert model.is_sparse and len(model.factors) == 1
    assert {"exact", "filter", "fpi", "vmp", "vmp_pymdp", "mmp"} <= set(inference.accepting(model))
    assert "kernel" not in inference.accepting(model) and "particle_filter" not in inference.accepting(model)


def test_every_accepting_scheme_localises_aimapp_as_the_paper_filter_does():
    ref_decisions, ref_beliefs, ref = _run("filter")
    assert ref.num_states > 5  # the map grew: inference ran on a sparse, growing model
    schemes = inference.accepting(ref.model)
    for name in schemes:
        decisions, beliefs, agent = _run(name)
        assert decisions == ref_decisions, name
        assert agent.num_states == ref.num_states
        for q, q_ref in zip(beliefs, ref_beliefs, strict=True):
            np.testing.assert_allclose(q, q_ref, atol=1e-12, err_msg=name)


def test_a_scheme_that_refuses_the_model_or_is_unknown_is_a_clear_error():
    cfg = replace(default_config("mini_warehouse"), scheme="kernel")
    with pytest.raises(ValueError, match="'kernel' does not accept AIMAPP's model; schemes that do: exact, filter"):
        AIMAPPAgent(cfg, model=initial_model(cfg, np.zeros(2)))
    with pytest.raises(KeyError, match="unknown inference scheme 'nope'"):
        AIMAPPAgent(replace(cfg, scheme="nope"))
    with pytest.raises(ValueError, match="AgentConfig.scheme: expected a non-empty string"):
        replace(cfg, scheme="")
    assert "scheme" not in default_config("mini_warehouse").to_dict()  # the paper's: earlier run keys stay
    assert replace(cfg, scheme="fpi").to_dict()["scheme"] == "fpi"
    from cogmap.agent.config import AgentConfig

    assert AgentConfig.from_dict(replace(cfg, scheme="fpi").to_dict()).scheme == "fpi"
    with pytest.raises(ValueError, match="'os:system' is not a registered inference scheme"):
        AgentConfig.from_dict({**cfg.to_dict(), "scheme": "os:system"})  # a file's name picks no code


def test_plugins_are_imported_only_by_dotted_name():
    from cogmap.plugins import import_plugins

    with pytest.raises(ValueError, match="expected a dotted module name"):
        import_plugins(["../evil.py"])


def test_command_line_runs_aimapp_with_fpi_and_refuses_an_unknown_scheme(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["explore", "--env", "mini_warehouse", "--steps", "3", "--scheme", "fpi", "--out", str(out),
                 "--quiet"]) == 0
    assert json.loads((out / "run.json").read_text())["config"]["scheme"] == "fpi"  # the run says how it ran
    capsys.readouterr()
    assert main(["explore", "--scheme", "nope", "--out", str(tmp_path / "x"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "unknown inference scheme 'nope' (--scheme); registered: exact, filter, fpi" in err

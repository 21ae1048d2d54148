"""Encoders by name: register_encoder's clear errors, and the agent building the configured one."""

from __future__ import annotations

import pytest

from cogmap.agent.aimapp import AIMAPPAgent
from cogmap.agent.config import AgentConfig
from cogmap.agent.encoder import (
    SSIMEncoder,
    available_encoders,
    make_encoder,
    register_encoder,
    unregister_encoder,
)
from cogmap.agent.testing import BoxWorld, CellEncoder, run

UNREGISTER = unregister_encoder  # what the suite's ``registered`` fixture removes with


def test_register_encoder_errors(registered):
    with pytest.raises(ValueError, match="non-empty string"):
        register_encoder("", lambda cfg: CellEncoder())
    with pytest.raises(TypeError, match="expected a callable factory"):
        register_encoder("cells", CellEncoder())  # an encoder, not a factory
    with pytest.raises(TypeError, match="expected a callable factory"):
        register_encoder("cells", "ssim")
    with pytest.raises(ValueError, match="built-in encoder"):
        register_encoder("ssim", lambda cfg: CellEncoder())
    register_encoder("cells", lambda cfg: CellEncoder(cfg.influence_radius / 2))
    registered.append("cells")
    with pytest.raises(ValueError, match="exists.*overwrite=True"):
        register_encoder("cells", lambda cfg: CellEncoder())
    with pytest.raises(KeyError, match="unknown encoder 'nope'.*cells, ssim"):
        make_encoder("nope", AgentConfig())
    with pytest.raises(KeyError, match="unknown encoder 'nope'"):
        AIMAPPAgent(AgentConfig(encoder="nope"))
    with pytest.raises(ValueError, match="built-in encoder"):
        unregister_encoder("ssim")
    with pytest.raises(KeyError, match="no encoder named 'nope'"):
        unregister_encoder("nope")
    register_encoder("bare", lambda cfg: object())
    registered.append("bare")
    with pytest.raises(TypeError, match="object is not an Encoder"):
        make_encoder("bare", AgentConfig())
    assert set(available_encoders()) >= {"ssim", "cells", "bare"}


def test_the_agent_builds_and_uses_the_configured_encoder(registered):
    assert isinstance(AIMAPPAgent(AgentConfig()).encoder, SSIMEncoder)
    assert AIMAPPAgent(AgentConfig(ssim_threshold=0.8)).encoder.threshold == 0.8

    @register_encoder("coarse_cells")
    def coarse(cfg):
        return CellEncoder(2.0)

    registered.append("coarse_cells")
    cfg = AgentConfig(encoder="coarse_cells")
    assert AgentConfig.from_dict(cfg.to_dict()) == cfg
    world = BoxWorld(6, 6, start=(1, 1))
    agent = AIMAPPAgent(cfg, seed=0)
    assert isinstance(agent.encoder, CellEncoder) and agent.encoder.cell == 2.0
    run(world, agent, 8)
    # the observation ids are the encoder's: one per 2 m cell visited
    assert agent.model.num_obs[0] == len(agent.encoder.ids) >= 2


def test_cli_explore_uses_an_encoder_from_a_plugin(tmp_path, monkeypatch, capsys, registered):
    import json

    from cogmap.cli import main

    (tmp_path / "strict_encoder_plugin.py").write_text(
        "from cogmap.agent.encoder import SSIMEncoder, register_encoder\n"
        "register_encoder('strict_ssim', lambda config: SSIMEncoder(0.999))\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    registered.append("strict_ssim")
    out = tmp_path / "run"
    code = main(["--plugin", "strict_encoder_plugin", "explore", "--encoder", "strict_ssim", "--steps", "3",
                 "--patience", "0", "--out", str(out), "--quiet"])
    assert code == 0, capsys.readouterr().err
    assert json.loads((out / "run.json").read_text())["config"]["encoder"] == "strict_ssim"
    metrics = json.loads((out / "metrics.json").read_text())
    # with a 0.999 threshold no two panoramas from different places match: one id per decision
    assert metrics["num_observations"] == 3 == len(list((out / "observations").glob("*.png")))
    # a goal run rebuilds the run's encoder by name and restores its observations
    from cogmap.goal import load_agent

    agent, _ = load_agent(out)
    assert agent.encoder.threshold == 0.999 and len(agent.encoder.images) == 3


def test_cli_explore_with_an_unknown_encoder_is_a_one_line_error(capsys, tmp_path):
    from cogmap.cli import main

    assert main(["explore", "--encoder", "nope", "--steps", "1", "--out", str(tmp_path / "run"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "unknown encoder 'nope'" in err and "ssim" in err

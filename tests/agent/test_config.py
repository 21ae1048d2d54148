"""AgentConfig: every field survives a (JSON) round trip, and the planner reads the collision preference."""

import json
from dataclasses import fields, replace

import numpy as np
import pytest

from cogmap.agent import planner
from cogmap.agent.aimapp import AIMAPPAgent
from cogmap.agent.config import AgentConfig
from cogmap.agent.testing import BoxWorld, CellEncoder, run
from cogmap.inference.learning import LearningRates
from cogmap.planning.mcts import MCTSConfig


def _other(value):
    """A value of the same kind that differs from ``value``."""
    if isinstance(value, bool):
        return not value
    if isinstance(value, int):
        return value + 3
    if isinstance(value, float):
        return value * 0.5 + 0.3
    if value is None:
        return 0.123
    if isinstance(value, tuple):
        return tuple(_other(v) for v in value)
    if isinstance(value, str):
        return value + "_other"
    raise TypeError(value)


def test_round_trip_keeps_every_field_through_json():
    base = AgentConfig()
    changed = {f.name: _other(getattr(base, f.name)) for f in fields(AgentConfig) if f.name not in ("learning", "mcts")}
    # the planner's settings, every one changed (share and backup to their other choice)
    changed["mcts"] = MCTSConfig(**{f.name: _other(getattr(base.mcts, f.name)) for f in fields(MCTSConfig)
                                    if f.name not in ("share", "backup")}, share="state", backup="mean")
    changed["view_bounds"] = (-1.0, -2.0, 3.0, 4.0)  # an outline, not any value
    changed["scheme"] = "fpi"  # another registered scheme (a file may name only registered ones)
    lr = LearningRates(**{f.name: _other(getattr(base.learning, f.name)) for f in fields(LearningRates)})
    cfg = AgentConfig(**changed, learning=lr)
    for f in fields(AgentConfig):  # every field really differs from its default
        assert getattr(cfg, f.name) != getattr(base, f.name), f.name
    back = AgentConfig.from_dict(json.loads(json.dumps(cfg.to_dict())))
    assert back == cfg
    assert back.learning.max_concentration == lr.max_concentration
    assert isinstance(back.learning.forward, tuple)


def test_saved_max_concentration_comes_back():
    cfg = AgentConfig(learning=replace(LearningRates(), max_concentration=3.0))
    assert AgentConfig.from_dict(json.loads(json.dumps(cfg.to_dict()))).learning.max_concentration == 3.0


def test_unknown_fields_are_refused_by_name():
    with pytest.raises(ValueError, match="AgentConfig: unknown field.*'colision_preference'"):
        AgentConfig.from_dict({"colision_preference": -3.0})
    with pytest.raises(ValueError, match="LearningRates: unknown field.*'max_conc'"):
        AgentConfig.from_dict({"learning": {"max_conc": 3.0}})


@pytest.mark.parametrize("kwargs, message", [
    (dict(collision_preference=float("nan")), "AgentConfig.collision_preference: expected a finite number, got nan"),
    (dict(mcts=MCTSConfig(gamma=float("inf"))), "AgentConfig.gamma: expected a finite number, got inf"),
    (dict(pose_sigma=float("nan")), "AgentConfig.pose_sigma: expected a finite number or None, got nan"),
    (dict(mcts=MCTSConfig(depth=2.5)), "AgentConfig.mcts_depth: expected an integer, got 2.5"),
    (dict(view_weighting="yes"), "AgentConfig.view_weighting: expected true or false, got 'yes'"),
    (dict(encoder=3), "AgentConfig.encoder: expected a string, got 3"),
    (dict(learning=LearningRates(floor=float("nan"))), "AgentConfig.learning.floor: expected a finite number"),
    (dict(learning=LearningRates(forward=(7.0, float("inf"), 5.0, -5.0))),
     "AgentConfig.learning.forward: expected finite numbers"),
])
def test_non_finite_or_mistyped_values_are_refused_naming_the_field(kwargs, message):
    with pytest.raises(ValueError) as err:
        AgentConfig(**kwargs)
    assert str(err.value).startswith(message)
    key, value = next(iter(kwargs.items()))
    if key == "mcts":  # in a manifest the planner's settings are flat: mcts_depth, gamma, ...
        key = message.split(":")[0].removeprefix("AgentConfig.")
        value = value.gamma if key == "gamma" else value.depth
    if key != "learning":  # the same from a manifest (JSON keeps NaN as NaN)
        with pytest.raises(ValueError, match="AgentConfig." + key):
            AgentConfig.from_dict(json.loads(json.dumps({key: value})))


@pytest.mark.parametrize("pref", [-10.0, -2.5])
def test_planner_uses_the_configured_collision_preference(pref):
    cfg = AgentConfig(collision_preference=pref)
    world = BoxWorld(6, 6, boxes=[(2.5, 2.5, 3.5, 3.5)], start=(1, 1))
    agent = AIMAPPAgent(cfg, encoder=CellEncoder(), seed=0)
    run(world, agent, 3)
    state = int(np.argmax(agent.q))
    flags = np.zeros(cfg.num_headings, dtype=bool)
    flags[0] = True  # heading 0 reported blocked
    action, efe = planner.decide(agent.model, agent.cfg, agent.q, agent.rng, agent.memory.views,
                                 agent.scanned_from(), None, state, flags, "explore")
    assert efe["arrays"].collision_pref == pref
    # the collision term of Eq. 6 for a surely blocked move is P(collision) * ln P~(collision);
    # the breakdown has the sign of G (a penalty is positive)
    assert planner.term_breakdown(agent.q, efe, 0)["collision"] == pytest.approx(-pref)
    assert planner.term_breakdown(agent.q, efe, 1)["collision"] == 0.0


def test_encoders_follow_the_protocol_and_an_incomplete_one_is_refused():
    from cogmap.agent.encoder import Encoder, SSIMEncoder

    assert isinstance(SSIMEncoder(), Encoder) and isinstance(CellEncoder(), Encoder)

    class Bare:  # only callable: the agent reads last_scores and saves images
        def __call__(self, image):
            return 0, False

    with pytest.raises(TypeError, match="Bare is not an Encoder: it lacks images, last_scores, match"):
        AIMAPPAgent(AgentConfig(), encoder=Bare())


def test_cell_encoder_match_stores_nothing():
    enc = CellEncoder(1.0)
    assert enc.match((0.2, 0.2)) == (-1, 0.0)
    assert enc((0.2, 0.2)) == (0, True)
    assert enc.match((0.7, 0.4)) == (0, 1.0) and enc.match((1.5, 0.2)) == (-1, 0.0)
    assert len(enc.ids) == 1


def test_the_default_encoder_is_implicit_in_saved_configs():
    """Run keys of the studies digest the saved config: the paper's encoder adds no key to it."""
    assert "encoder" not in AgentConfig().to_dict()
    assert AgentConfig.from_dict(AgentConfig().to_dict()).encoder == "ssim"
    assert AgentConfig(encoder="mine").to_dict()["encoder"] == "mine"


def test_no_known_outline_is_implicit_in_saved_configs_and_a_bad_one_is_refused():
    assert "view_bounds" not in AgentConfig().to_dict()
    assert AgentConfig.from_dict(AgentConfig().to_dict()).view_bounds is None
    assert AgentConfig(view_bounds=[0, 0, 5, 4]).view_bounds == (0.0, 0.0, 5.0, 4.0)
    with pytest.raises(ValueError, match="view_bounds"):
        AgentConfig(view_bounds=(0, 0, -1, 4))


def test_retired_fields_of_saved_configs_are_dropped_with_a_warning():
    saved = AgentConfig().to_dict() | {"view_frontier_reach": 6.0}
    with pytest.warns(UserWarning, match="'view_frontier_reach' is retired"):
        assert AgentConfig.from_dict(saved) == AgentConfig()

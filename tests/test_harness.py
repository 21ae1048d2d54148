"""The one episode loop (cogmap.harness): AIMAPP and the baselines through one Policy protocol."""

import numpy as np
import pytest

from cogmap.agent.aimapp import AIMAPPAgent
from cogmap.agent.policy import AgentPolicy
from cogmap.baselines import FrontierExplorer, OracleTour, RandomWalk, run_policy
from cogmap.explore import default_config, make_sim, run_agent
from cogmap.harness import Command, Policy, coverage_tracker, run_episode

ENV = "mini_warehouse"


class Scripted:
    """Stays ``stays`` times, then drives one step east in the world frame, then is done."""

    label = "scripted"

    def __init__(self, stays: int):
        self.stays, self.calls, self.seen = stays, 0, []

    def sense(self, sim, moved):
        self.seen.append(moved)
        return sim.true_pose()

    def step(self, pose) -> Command:
        self.calls += 1
        row = dict(belief_x=pose[0], belief_y=pose[1], state=-1, action=-1, mode="scripted", num_states=0, num_obs=0)
        if self.calls <= self.stays:
            return Command(None, row=row, decision="stay")
        if self.calls == self.stays + 1:
            return Command(pose[:2] + [1.0, 0.0], "world", row, decision="move")
        return Command(None, row=dict(row, mode="done"), done=True)


@pytest.fixture
def sim():
    s = make_sim(ENV, default_config(ENV), 0)
    yield s
    s.close()


def test_agent_and_baselines_follow_one_protocol():
    agent = AIMAPPAgent(default_config(ENV), seed=0)
    for p in (AgentPolicy(agent), RandomWalk(), FrontierExplorer(), OracleTour(), Scripted(0)):
        assert isinstance(p, Policy), type(p).__name__


def test_harness_executes_records_and_ends_when_the_policy_is_done(sim):
    pol = Scripted(stays=2)
    decisions = []
    ep = run_episode(sim, pol, 10, on_step=decisions.append)
    assert [r["mode"] for r in ep.rows] == ["scripted"] * 3 + ["done"]
    assert decisions == ["stay", "stay", "move"]  # a finished policy's step is recorded, not executed
    assert pol.seen == [None, True, True, True]  # the outcome of each executed command is handed back
    assert ep.distance[:3] == [0.0, 0.0, 0.0] and ep.distance[-1] == pytest.approx(1.0, abs=0.02)
    assert sim.step_count == 3
    assert len(ep.coverage) == len(ep.rows) + 1  # plus the sweep after the last step
    assert [r["step"] for r in ep.rows] == [0, 1, 2, 3]


def test_stop_rules(sim):
    ep = run_episode(sim, Scripted(stays=5), 10, stop=lambda d: d == "stay")
    assert len(ep.rows) == 1
    ep = run_episode(sim, Scripted(stays=5), 10, stop_coverage=0.0)  # reached before the first decision
    assert ep.rows == [] and len(ep.coverage) == 1


def test_coverage_is_kept_per_simulator_without_touching_it(sim):
    agent = AIMAPPAgent(default_config(ENV), seed=0)
    ep = run_agent(sim, agent, 2, progress=False)
    tracker = coverage_tracker(sim)
    assert not any(name.startswith("_coverage") for name in vars(sim))
    assert coverage_tracker(sim) is tracker  # a later run in the same simulator keeps adding to it
    ep = run_agent(sim, agent, 1, progress=False, episode=ep)
    assert len(ep.rows) == 3 and ep.coverage[-1] >= ep.coverage[0] > 0
    other = make_sim(ENV, default_config(ENV), 0)
    try:
        assert coverage_tracker(other) is not tracker and coverage_tracker(other).coverage == 0.0
    finally:
        other.close()


def test_a_silent_lidar_adds_no_coverage_for_any_policy(sim):
    sim.inject_fault("lidar", 0, 3)
    ep = run_policy(sim, RandomWalk(1.0, seed=3), 5)
    assert ep.coverage[:3] == [0.0, 0.0, 0.0]  # nothing sensed during the fault
    assert ep.coverage[3] > 0.0


def test_baseline_rows_keep_their_fields(sim):
    ep = run_policy(sim, RandomWalk(1.0, seed=3), 3)
    row = ep.rows[0]
    assert row["mode"] == "random" and row["state"] == -1 and row["num_states"] == 0
    assert np.allclose([row["belief_x"], row["belief_y"]], [row["odom_x"], row["odom_y"]])
    assert ep.num_states == [0, 0, 0]

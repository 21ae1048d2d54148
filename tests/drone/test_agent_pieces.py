"""The drone agent's voxel memory and the potential-field baseline."""

import numpy as np
import pytest

from cogmap.drone import DroneAgent
from cogmap.drone.methods import make_policy
from cogmap.genmodel.voxel_map import VoxelMap
from cogmap.planning.drone_policies import PotentialField, StraightLine


class _Scan:
    def __init__(self, points):
        self.points = np.asarray(points, float)


def test_voxel_memory_counts_repeats_once_and_forgets_old_scans():
    m = VoxelMap(memory=2)
    m.add([[1.0, 0, 0], [1.01, 0.01, 0.0]])  # one voxel
    m.add([[1.02, 0.02, 0.01], [5.0, 0, 0]])  # the same voxel again, and a new one
    assert len(m.points) == 2
    m.add([[9.0, 0, 0]])  # the first scan drops out; the second still holds (1, 0, 0)
    assert len(m.points) == 3
    m.add([[9.0, 0, 0]])
    assert len(m.points) == 1 and len(m.near([0.0, 0, 0], 5.0)) == 0
    with pytest.raises(ValueError, match="memory"):
        VoxelMap(memory=0)


def test_potential_field_turns_away_from_a_wall_and_straight_line_does_not():
    ys, zs = np.meshgrid(np.arange(-3, 3.01, 0.15), np.arange(3, 7.01, 0.15))
    wall = np.stack([np.full(ys.size, 2.0), ys.ravel(), zs.ravel()], 1)
    pos, tgt = np.array([0.0, 0.5, 5.0]), np.array([30.0, 0.5, 5.0])
    pf = PotentialField()
    pf.observe(_Scan(wall))
    step = pf.decide(pos, tgt).waypoint - pos
    assert step[0] < -1.0  # repelled: the wall 2 m ahead outweighs the pull of the target
    straight = StraightLine().decide(pos, tgt).waypoint - pos
    np.testing.assert_allclose(straight, [3.0, 0, 0])


def test_agent_first_decision_heads_for_an_open_target():
    agent = DroneAgent(seed=0)
    dec = agent.decide(np.array([0.0, 0, 5]), np.array([0.0, 40, 5]))
    step = dec.waypoint - np.array([0.0, 0, 5])
    assert step[1] / np.linalg.norm(step) > 0.9 and dec.speed == 2.0 and dec.plan_ms > 0
    assert dec.state["d_obs"] == 10.0 and dec.state["S"] == pytest.approx(0.9527, abs=1e-4)
    with pytest.raises(ValueError, match="unknown drone method"):
        make_policy("hover")

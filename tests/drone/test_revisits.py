"""What the agent adds to the published planner: novelty (inhibition of return) in the EFE, the
clearance along a candidate's path, ties kept in the fallback cascade, and contacts as obstacles."""

import numpy as np
import pytest

from cogmap.drone import DroneAgent
from cogmap.drone.agent import DroneAgentConfig
from cogmap.genmodel.suitability import path_clearances, suitability, waypoint_suitability
from cogmap.planning import drone_efe as E
from cogmap.planning.drone_planner import DronePlannerConfig, plan_waypoints
from cogmap.planning.drone_waypoints import filter_waypoints


def test_novelty_is_one_where_the_drone_has_not_been_and_decays_with_visits():
    W = np.array([[0.0, 0, 5], [3.0, 0, 5], [10.0, 0, 5]])
    np.testing.assert_allclose(E.novelty(W, None), 1.0)
    np.testing.assert_allclose(E.novelty(W, np.zeros((0, 3))), 1.0)
    once = E.novelty(W, W[:1])
    assert once[0] == pytest.approx(0.5)  # one visit halves it (prior count 1)
    assert once[1] == pytest.approx(1.0 / (1.0 + np.exp(-4.5)))  # 3 m away, kernel width 1 m
    assert once[2] == pytest.approx(1.0)
    thrice = E.novelty(W, np.repeat(W[:1], 3, 0))
    assert thrice[0] == pytest.approx(0.25) and thrice[0] < once[0]
    np.testing.assert_allclose(E.visit_counts(W, np.repeat(W[:1], 3, 0))[0], 3.0)


def test_novelty_scales_the_whole_efe_and_keeps_it_negative():
    pref, bonus, m = np.array([0.3, 0.8]), np.array([0.0, 0.1]), np.array([2.0, 3.0])
    G1, p1, e1 = E.efe(pref, bonus, m, 6.0)
    eta = np.array([1.0, 0.25])
    G, p, e = E.efe(pref, bonus, m, 6.0, novelty=eta)
    np.testing.assert_allclose(G, eta * G1)
    np.testing.assert_allclose(p, eta * p1)
    np.testing.assert_allclose(e, eta * e1)
    assert (G <= 0).all()


def _two_cycle_case():
    """In front of a wall of trees (voxels at y = 4) with the target behind it: the best step of
    the published planner from a point is the place it came from."""
    xs, zs = np.meshgrid(np.arange(-8, 8.01, 0.3), np.arange(0, 10.01, 0.3))
    wall = np.stack([xs.ravel(), np.full(xs.size, 4.0), zs.ravel()], 1)
    return np.array([0.0, 0.0, 5.0]), np.array([0.0, 30.0, 5.0]), wall


def test_a_visited_place_loses_to_a_novel_one():
    from cogmap.genmodel.suitability import clearance, density

    pos, tgt, wall = _two_cycle_case()
    d, rho = clearance(pos, wall), density(pos, wall)
    s = suitability(d, rho)
    paper = plan_waypoints(pos, tgt, wall, d, rho, s, 6.0, 40.0, np.random.default_rng(0),
                           DronePlannerConfig.published())
    best = paper.actions[0]
    # the drone has been at the published planner's first choice three times
    visited = np.repeat(best[None], 3, 0)
    ours = plan_waypoints(pos, tgt, wall, d, rho, s, 6.0, 40.0, np.random.default_rng(0),
                          DronePlannerConfig(), visited)
    assert np.linalg.norm(ours.actions[0] - best) > 1.0
    # without visits the novelty changes nothing: the same choice as published
    fresh = plan_waypoints(pos, tgt, wall, d, rho, s, 6.0, 40.0, np.random.default_rng(0),
                           DronePlannerConfig(path_clearance=False, keep_ties=False))
    np.testing.assert_allclose(fresh.actions, paper.actions)


def test_path_clearance_sees_an_obstacle_between_the_drone_and_a_clear_waypoint():
    pos = np.array([0.0, 0, 5])
    W = np.array([[0.0, 4.0, 5], [4.0, 0, 5]])
    pole = np.array([[0.0, 2.0, 5.0]])  # 2 m from both the drone and the first waypoint, on its path
    # the first path runs through the pole; the second passes it no closer than the drone is now
    np.testing.assert_allclose(path_clearances(pos, W, pole), [0.0, 2.0], atol=1e-9)
    ends = waypoint_suitability(W, pole, 2.0, [50.0, 0, 5], pos)
    path = waypoint_suitability(W, pole, 2.0, [50.0, 0, 5], pos, along_path=True)
    assert path[0] < ends[0] - 0.01 and path[1] == pytest.approx(ends[1])
    np.testing.assert_allclose(path[0], waypoint_suitability(W[:1], pole, 0.0, [50.0, 0, 5], pos))  # clearance 0
    assert np.isinf(path_clearances(pos, W, np.zeros((0, 3)))).all()


def test_fallback_ties_are_kept_for_the_efe_ranking():
    pos, tgt = np.zeros(3), np.array([50.0, 0, 0])
    W = np.array([[0.0, 0, -1], [1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0], [-1.0, 0, 0]])
    S = np.array([0.1, 0.1, 0.1, 0.1, 0.05])  # every candidate below 0.2, four tied for the best
    first, rule = filter_waypoints(W, S, pos, tgt, 0.0)
    assert rule == "fallback argmax" and list(first) == [0]  # the first of the tie, straight down
    tied, rule = filter_waypoints(W, S, pos, tgt, 0.0, keep_ties=True)
    assert rule == "fallback argmax" and list(tied) == [0, 1, 2, 3]
    S3 = np.array([0.5, 0.45, 0.45, 0.45, 0.1])
    assert list(filter_waypoints(W, S3, pos, tgt, 0.0)[0]) == [0, 1, 2]
    assert list(filter_waypoints(W, S3, pos, tgt, 0.0, keep_ties=True)[0]) == [0, 1, 2, 3]


def test_a_contact_becomes_an_obstacle_voxel():
    agent = DroneAgent(seed=0)
    pos = np.array([0.0, 0, 5])
    assert agent.sense(pos)[1] == 10.0  # nothing sensed
    agent.observe_contact([0.0, 0.3, 5.0])
    V, d_obs, _, S = agent.sense(pos)
    assert len(V) == 1 and d_obs == pytest.approx(0.3)
    assert S == pytest.approx(suitability(0.3, 1 / (4 / 3 * np.pi * 5 ** 3)))
    agent.reset()
    assert agent.sense(pos)[1] == 10.0  # forgotten with the episode
    blind = DroneAgent(DroneAgentConfig(contact_memory=False), seed=0)
    blind.observe_contact([0.0, 0.3, 5.0])
    assert blind.sense(pos)[1] == 10.0


def test_the_agent_remembers_where_it_decided():
    agent = DroneAgent(seed=0)
    tgt = np.array([0.0, 40, 5])
    for p in ([0.0, 0, 5], [0.0, 3, 5]):
        agent.decide(np.array(p), tgt)
    np.testing.assert_allclose(agent.visited, [[0.0, 0, 5], [0.0, 3, 5]])
    agent.reset()
    assert agent.visited == []


def test_near_the_target_a_blocked_path_earns_no_proximity_bonus():
    pos, tgt = np.array([0.0, 0, 5]), np.array([3.0, 3.0, 5])
    W = np.array([[2.6, 2.6, 5], [0.0, 2.5, 5]])  # both reduce the distance, the first ends 0.6 m from the target
    contact = np.array([[0.3, -0.1, 5.0]])  # just touched, beside the way to the target
    d_obs = float(np.hypot(0.3, 0.1))
    ends = waypoint_suitability(W, contact, d_obs, tgt, pos)
    path = waypoint_suitability(W, contact, d_obs, tgt, pos, along_path=True)
    assert ends[0] >= 0.6  # published: the bonuses lift the blocked waypoint over the 0.6 threshold
    assert path[0] < 0.3  # its path runs through the contact: no bonus, and the clearance of a touch
    assert path[1] == pytest.approx(ends[1]) and path[1] > path[0] + 0.2  # the path leaving the contact keeps it

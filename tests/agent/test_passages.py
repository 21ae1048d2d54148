"""Places in a corridor sit on its centre line (issue: corridors must not hold two rows of look-alike
states): the pure centring rule, and a pybullet corridor explored with and without it."""

from __future__ import annotations

import json

import numpy as np
import pytest

from cogmap.agent.mapping import centre_in_passage


def _walls(y_low, y_high, x0=-3.0, x1=3.0, step=0.05):
    x = np.arange(x0, x1, step)
    return np.vstack([np.stack([x, np.full_like(x, y_low)], 1), np.stack([x, np.full_like(x, y_high)], 1)])


def test_a_pose_in_a_corridor_moves_to_its_centre_line():
    pts = _walls(-0.9, 0.9)  # a 1.8 m corridor along x
    u = np.array([np.cos(np.pi / 6), np.sin(np.pi / 6)])  # a move at 30 degrees from the centre line
    p = u * 1.0
    c = centre_in_passage(p, u, pts, max_width=2.5)
    # moved across the move (not along it) onto y = 0
    assert abs(c[1]) < 0.03 and abs((c - p) @ u) < 1e-9
    # along the corridor: already centred, nothing moves
    np.testing.assert_allclose(centre_in_passage([1.0, 0.0], [1.0, 0.0], pts, 2.5), [1.0, 0.0], atol=1e-9)


def test_open_space_one_wall_and_wide_halls_leave_the_pose_alone():
    p, u = np.array([0.5, 0.3]), np.array([1.0, 0.0])
    np.testing.assert_array_equal(centre_in_passage(p, u, np.zeros((0, 2)), 2.5), p)  # nothing sensed
    one_side = _walls(-0.9, 50.0)[:120]  # only the wall at y = -0.9
    np.testing.assert_array_equal(centre_in_passage(p, u, one_side, 2.5), p)
    np.testing.assert_array_equal(centre_in_passage(p, u, _walls(-2.0, 2.0), 2.5), p)  # 4 m: a hall
    np.testing.assert_array_equal(centre_in_passage(p, u, _walls(-0.9, 0.9), 0.0), p)  # switched off
    c = centre_in_passage(p, u, _walls(-0.9, 0.9), 2.5, max_shift=0.1)
    np.testing.assert_allclose(c, [0.5, 0.2])  # the shift is bounded
    # a doorway: walls across the move only 0.15 m thick, as at an opening in a thin wall
    door = _walls(-0.8, 0.8, x0=0.45, x1=0.6)
    np.testing.assert_array_equal(centre_in_passage(p, u, door, 2.5), p)


CORRIDOR = {"name": "straight_corridor",
            "walls": [{"from": [0, 0], "to": [14, 0]}, {"from": [14, 0], "to": [14, 1.8]},
                      {"from": [14, 1.8], "to": [0, 1.8]}, {"from": [0, 1.8], "to": [0, 0]}],
            "starts": [[0.8, 0.5, 0.0]]}


def _corridor_states(tmp_path, passage_width):
    pytest.importorskip("pybullet", reason="needs the sim extra")
    from dataclasses import replace

    from cogmap.agent.aimapp import AIMAPPAgent
    from cogmap.explore import default_config, make_sim, run_agent

    path = tmp_path / "corridor.json"
    path.write_text(json.dumps(CORRIDOR))
    cfg = replace(default_config(str(path)), passage_width=passage_width)
    sim = make_sim(str(path), cfg, 0)
    try:
        agent = AIMAPPAgent(cfg, seed=0)
        run_agent(sim, agent, 25, progress=False)
        return agent.poses.copy()
    finally:
        sim.close()


def test_a_pybullet_corridor_holds_one_row_of_states_on_its_centre_line(tmp_path):
    """A 1.8 m x 14 m corridor, the robot starting 0.4 m off its centre line: with the centring,
    every state past the first metre lies within 0.2 m of the centre line; with the paper's
    placement (one influence radius along each heading) they follow the start's offset."""
    centred = _corridor_states(tmp_path, 2.5)
    inner = centred[centred[:, 0] > 1.8]
    assert len(inner) >= 8
    assert np.abs(inner[:, 1] - 0.9).max() <= 0.2
    paper = _corridor_states(tmp_path, 0.0)
    assert np.abs(paper[paper[:, 0] > 1.8][:, 1] - 0.9).max() >= 0.3

import numpy as np
import pytest

from cogmap.envs.gridworld import STAY, GridWorld, rooms_map


def test_rooms_map_has_doors_and_is_connected():
    walls = rooms_map(2, 2, 4)
    assert walls.shape == (11, 11)
    w = GridWorld(walls, n_colors=5, seed=0)
    assert w.n_cells == 16 * 4 + 4  # four 4x4 rooms and four doors
    B = w.B()
    reach = {0}
    frontier = [0]
    while frontier:
        c = frontier.pop()
        for a in range(5):
            n = w.next_cell(c, a)
            if n not in reach:
                reach.add(n)
                frontier.append(n)
    assert len(reach) == w.n_cells
    assert np.allclose(B.sum(axis=0), 1.0)
    assert np.allclose(B[:, :, STAY], np.eye(w.n_cells))


def test_model_matches_dynamics_and_observations():
    w = GridWorld(n_colors=4, seed=3)
    B, A = w.B(), w.A()
    rng = np.random.default_rng(0)
    w.reset(seed=1)
    for _ in range(200):
        c = w.cell_of(w.true_pose())
        assert A[w.observe(), c] == 1.0
        a = int(rng.integers(5))
        res = w.step_action(a)
        assert B[w.cell_of(w.true_pose()), c, a] == 1.0
        assert res.success == (a == STAY or w.cell_of(w.true_pose()) != c)


def test_walls_block_and_obstacle_signal():
    w = GridWorld(seed=0)
    w.reset(start=w.cell_of((1, 1)))  # bottom-left corner of the first room
    sig = w.obstacle_signal()
    assert sig.tolist() == [0, 0, 1, 1]  # east, north free; west, south walls
    res = w.step_action(2)
    assert not res.success and w.true_pose()[:2].tolist() == [1, 1]
    assert w.step_action(0).success and w.odometry()[:2].tolist() == [2, 1]


def test_gridworld_dropouts():
    w = GridWorld(seed=0)
    w.reset(seed=0)
    w.inject_fault("camera", 1, 2)
    w.inject_fault("odometry", 2, 1)
    assert w.observe() is not None
    w.step_action(4)
    assert w.observe() is None and w.odometry() is not None
    w.step_action(4)
    assert w.observe() is None and w.odometry() is None
    w.step_action(4)
    assert w.observe() is not None and w.odometry() is not None
    with pytest.raises(ValueError):
        w.step_action(5)

import gymnasium as gym
import matplotlib
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from cogmap.envs import MAZE_ID, exploration_ratio, make_maze
from cogmap.envs.maze import CELLS, CORRIDOR, TABLE_II
from cogmap.envs.maze_render import save_maze_png
from cogmap.envs.maze_sim import LIDAR_RANGE, N_BEAMS, ActuationNoise, MazeSim
from cogmap.envs.maze_traversal import cell_path, traverse

matplotlib.use("Agg")


def _connected(maze):
    seen, todo = {(0, 0)}, [(0, 0)]
    while todo:
        for nb in maze.neighbours(*todo.pop()):
            if nb not in seen:
                seen.add(nb)
                todo.append(nb)
    return len(seen) == maze.n**2


@pytest.mark.parametrize("complexity", sorted(CELLS))
@pytest.mark.parametrize("corridor", sorted(CORRIDOR))
def test_table_ii_sizes_and_connectivity(complexity, corridor):
    m = make_maze(4, complexity, corridor)
    expected = {("simple", "small"): 0.25, ("simple", "medium"): 0.5, ("simple", "large"): 0.75,
                ("moderate", "small"): 0.5, ("moderate", "medium"): 1.0, ("moderate", "large"): 1.5,
                ("complex", "small"): 1.0, ("complex", "medium"): 2.0, ("complex", "large"): 3.0}
    assert m.size == pytest.approx(expected[(complexity, corridor)])
    assert (m.map_side, m.tiles, m.step_budget) == TABLE_II[(complexity, corridor)]
    assert _connected(m)


def test_mazes_are_seeded():
    a, b, c = make_maze(1), make_maze(1), make_maze(2)
    assert np.array_equal(a.walls, b.walls)
    assert not (a.walls.shape == c.walls.shape and np.allclose(a.walls, c.walls))
    with pytest.raises(ValueError, match="complexity"):
        make_maze(0, "hard")


def test_lidar_against_geometry():
    # the unit maze has boundary walls at 0 and 1 (thickness 0.006): from (0.5/6, 0.5/6) facing
    # east, beam 10 points west and sees the outer wall at 1/12 - 0.003
    m = make_maze(0)
    with MazeSim(m) as sim:
        sim.reset((0.5 / 6, 0.5 / 6, 0.0))
        scan = sim.lidar()
        assert scan.shape == (N_BEAMS,)
        assert scan[10] == pytest.approx(1 / 12 - 0.003, abs=1e-6)
        assert scan[15] == pytest.approx(1 / 12 - 0.003, abs=1e-6)  # beam 15 points south
        assert np.all(scan <= LIDAR_RANGE) and np.all(scan > 0)
        # an open beam returns exactly the range: place the agent facing a long open direction
        open_any = False
        for i in range(m.n):
            for j in range(m.n):
                sim.reset((*m.cell_centre(i, j), 0.0))
                open_any |= bool(np.any(sim.lidar() == LIDAR_RANGE))
        assert open_any


def test_rotation_before_translation_and_walls_block():
    m = make_maze(0)
    with MazeSim(m) as sim:
        sim.reset((0.5 / 6, 0.5 / 6, 0.0))
        pose, blocked = sim.step((np.pi / 2, 0.01))  # turn north first, then move
        assert pose[0] == pytest.approx(0.5 / 6) and pose[1] == pytest.approx(0.5 / 6 + 0.01)
        assert not blocked
        pose, blocked = sim.step((np.pi, 0.5))  # face south, run into the outer wall
        assert blocked and 0.003 <= pose[1] < 0.0035
        with pytest.raises(ValueError, match="forward"):
            sim.step((0.0, -0.1))


def test_traversal_long_and_within_maze():
    m = make_maze(3)
    tr = traverse(m, 1500, seed=2, noise=ActuationNoise(0.005, 0.05))
    assert tr.poses.shape == (1500, 3) and tr.controls.shape == (1499, 2) and tr.scans.shape == (1500, N_BEAMS)
    assert np.all((tr.poses[:, :2] > 0) & (tr.poses[:, :2] < m.size))
    assert exploration_ratio(m, tr.poses) > 0.5  # crosses most of the maze
    tr2 = traverse(m, 1500, seed=2, noise=ActuationNoise(0.005, 0.05))
    assert np.array_equal(tr.poses, tr2.poses)
    path = cell_path(m, (0, 0), (5, 5))
    assert path[0] == (0, 0) and path[-1] == (5, 5)
    assert all(b in m.neighbours(*a) for a, b in zip(path, path[1:], strict=False))


def test_gym_maze_check_env_and_png(tmp_path):
    env = gym.make(MAZE_ID, render_mode="rgb_array")
    try:
        check_env(env.unwrapped)
        obs, info = env.reset(seed=3)
        assert obs.shape == (N_BEAMS,) and info["true_pose"].shape == (3,)
        img = env.unwrapped.render()
        assert img.ndim == 3 and img.dtype == np.uint8
        m = env.unwrapped.maze
        out = save_maze_png(m, tmp_path / "maze.png", paths=[("path", np.array(env.unwrapped.path), "r")],
                            pose=info["true_pose"], scan=obs)
        import matplotlib.image as mpimg

        assert mpimg.imread(out)[..., :3].std() > 0.05
    finally:
        env.close()

import numpy as np
import pytest

from cogmap.envs.geometry import ShapeSet
from cogmap.envs.layouts import LAYOUTS
from cogmap.envs.robot import OdometryNoise
from cogmap.envs.sim import SimConfig


@pytest.mark.parametrize("name", sorted(LAYOUTS))
def test_lidar_hits_land_on_occupied_cells(make_sim, name):
    sim = make_sim(name, seed=0)
    g = sim.grid
    occ = np.pad(g.occupied, 1)
    n_hits = 0
    for start in range(len(sim.layout.starts))[:3]:
        sim.teleport(sim.layout.starts[start])
        pts, names = sim.lidar_hits()
        hit = np.array([n is not None for n in names])
        assert hit.mean() > 0.5  # enclosed rooms: most beams hit within 12 m
        rc = g.world_to_cell(pts[hit]) + 1
        near = np.zeros(len(rc), bool)
        for dr in (-1, 0, 1):
            for dc in (-1, 0, 1):
                near |= occ[rc[:, 0] + dr, rc[:, 1] + dc]
        assert near.all(), pts[hit][~near]
        n_hits += hit.sum()
        # the hit points lie on the named shape's surface (exact geometry agrees)
        d = np.array([ShapeSet([sim.layout.shape(n)]).distance(p)[0]
                      for p, n in zip(pts[hit], np.array(names, object)[hit], strict=True)])
        assert np.abs(d).max() < 0.02
    assert n_hits > 500


def test_lidar_range_to_wall_is_exact(make_sim):
    sim = make_sim("mini_warehouse", seed=0, start=(1.0, 3.0, 0.0))
    r = sim.lidar()
    ang = sim.lidar_angles()
    assert r.shape == (360,) and ang[0] == 0.0
    assert r[180] == pytest.approx(1.0, abs=1e-3)  # west wall inner face at x = 0
    # east: central box face at x = 3.3 - 0.6
    assert r[0] == pytest.approx(3.3 - 0.6 - 1.0, abs=1e-3)
    assert (r >= sim.config.robot_radius).all() and (r <= 12.0).all()


def test_blocked_move_stops_outside_obstacle(make_sim):
    sim = make_sim("mini_warehouse", seed=0)
    sim.teleport((1.0, 3.0, 0.0))
    res = sim.move_to((5.5, 3.0), frame="world")  # straight through the central box
    assert not res.success
    assert res.blocked_by == "central_box"
    assert res.distance < res.requested
    end = sim.true_pose()
    assert np.allclose(end[:2], res.end[:2])
    clear = ShapeSet(sim.layout.shapes).distance(end[:2])[0]
    assert sim.config.robot_radius <= clear < sim.config.robot_radius + 0.06
    # pybullet agrees: no penetration between the robot cylinder and the box
    assert sim.scene.closest_distance("central_box") >= -1e-6
    # moving away succeeds and covers the full distance
    res2 = sim.move_to(end[:2] - np.array([0.8, 0.0]), frame="world")
    assert res2.success and res2.distance == pytest.approx(0.8)


def test_free_move_and_stay(make_sim):
    sim = make_sim("mini_warehouse", seed=0, start=(1.0, 1.0, 0.0))
    res = sim.step_action(3)  # 90 degrees: north
    assert res.success and np.allclose(sim.true_pose(), [1.0, 1.5, np.pi / 2])
    res = sim.step_action(12)
    assert res.success and res.distance == 0.0
    assert np.allclose(sim.true_pose(), [1.0, 1.5, np.pi / 2])
    assert sim.step_count == 2


def same_pose(a, b):
    d = np.asarray(a, float) - np.asarray(b, float)
    d[2] = (d[2] + np.pi) % (2 * np.pi) - np.pi
    return np.allclose(d, 0.0, atol=1e-9)


def test_perfect_odometry_tracks_truth(make_sim):
    sim = make_sim("house", seed=1)
    for a in np.random.default_rng(0).integers(13, size=20):
        sim.step_action(int(a))
        assert same_pose(sim.odometry(), sim.true_pose())


@pytest.mark.parametrize("slip,bias", [(0.05, 0.0), (0.0, 0.03), (-0.03, -0.02)])
def test_drift_matches_configured_rate(make_sim, slip, bias):
    cfg = SimConfig(noise=OdometryNoise(slip=slip, heading_bias=bias))
    sim = make_sim("large_warehouse", cfg, seed=0, start=(4.5, 1.7, 0.0))
    start = sim.true_pose()
    total = 0.0
    for _ in range(10):  # 10 m east along the bottom aisle, in the world frame
        res = sim.move_to(sim.true_pose()[:2] + [1.0, 0.0], frame="world")
        assert res.success
        total += res.distance
    assert total == pytest.approx(10.0)
    true_d = np.hypot(*(sim.true_pose()[:2] - start[:2]))
    odom = sim.odometry()
    yaw_err = (odom[2] - sim.true_pose()[2] + np.pi) % (2 * np.pi) - np.pi
    assert yaw_err == pytest.approx(bias * total, abs=1e-9)
    odom_d = np.hypot(*(odom[:2] - start[:2]))
    # ten 1 m segments, each (1 + slip) m long in odometry, turning by `bias` rad per segment
    chord = 10.0 if bias == 0 else np.sin(10 * bias / 2) / np.sin(bias / 2)
    assert true_d == pytest.approx(10.0)
    assert odom_d == pytest.approx((1 + slip) * chord, rel=1e-9)
    if bias == 0:
        assert np.allclose(odom[:2] - start[:2], [(1 + slip) * true_d, 0.0])


def test_random_odometry_noise_is_seeded(make_sim):
    cfg = SimConfig(noise=OdometryNoise(trans_std=0.05, rot_std=0.02))
    runs = []
    for _ in range(2):
        sim = make_sim("house", cfg, seed=7)
        for a in range(10):
            sim.step_action(a)
        runs.append(sim.odometry())
    assert np.array_equal(runs[0], runs[1])
    assert not np.allclose(runs[0], sim.true_pose())


def test_odom_frame_commands_follow_the_robots_belief(make_sim):
    cfg = SimConfig(noise=OdometryNoise(heading_bias=0.1))
    sim = make_sim("large_warehouse", cfg, seed=0, start=(4.5, 1.7, 0.0))
    sim.move_to(sim.odometry()[:2] + [3.0, 0.0])
    # the controller reaches the waypoint in its own frame, error hides in the truth
    odom = sim.odometry()
    sim.move_to(odom[:2] + [2.0, 0.0])
    assert sim.odometry()[0] == pytest.approx(odom[0] + 2.0, abs=0.05)
    assert abs(sim.true_pose()[1] - 1.7) > 0.05


def test_lidar_dropout_returns_none_then_fresh_data(make_sim):
    sim = make_sim("mini_warehouse", seed=0, start=(1.0, 1.0, 0.0))
    sim.inject_fault("lidar", start_step=1, length=2)
    before = sim.lidar()
    assert before is not None
    seen = []
    for _ in range(4):
        sim.step_action(3)  # north, 0.5 m each
        seen.append(sim.lidar())
    assert seen[0] is None and seen[1] is None
    assert sim.obstacle_signal() is not None
    assert seen[2] is not None and seen[3] is not None
    assert not np.allclose(seen[2], before)  # not stale: the robot moved meanwhile
    fresh = sim.scene.cast(sim.true_pose()[:2], sim.true_pose()[2] + sim.lidar_angles(),
                           sim.config.lidar_height, sim.config.robot_radius + 0.01, 12.0)[0]
    assert np.array_equal(seen[3], fresh)


def test_camera_and_odometry_dropouts(make_sim):
    sim = make_sim("house", seed=0)
    sim.inject_fault("camera", 0, 1)
    sim.inject_fault("odometry", 1, 2)
    assert sim.panorama() is None and sim.odometry() is not None
    sim.step_action(0)
    assert sim.panorama() is not None and sim.odometry() is None
    sim.step_action(6)
    assert sim.odometry() is None and sim.lidar() is not None
    sim.step_action(12)
    assert same_pose(sim.odometry(), sim.true_pose())  # integration continued
    with pytest.raises(ValueError):
        sim.inject_fault("sonar", 0, 1)


def test_obstacle_signal_sees_near_wall(make_sim):
    sim = make_sim("mini_warehouse", seed=0, start=(0.6, 3.0, 0.0))  # 0.6 m from the west wall
    sig = sim.obstacle_signal()
    assert sig.shape == (12,) and sig.dtype == np.int8
    assert sig[6] == 1 and sig[0] == 0  # west blocked, east free
    assert sim.step_action(6).success is False


def test_moving_obstacle_updates_grid_and_lidar(make_sim):
    sim = make_sim("mini_warehouse", seed=0)
    old = sim.layout.shape("central_box")
    sim.teleport((1.0, 3.0, 0.0))
    assert sim.lidar()[0] < 2.0
    sim.schedule_obstacle_move("central_box", (5.0, 5.2), at_step=2)
    sim.step_action(12)
    assert sim.grid.occupied[tuple(sim.grid.world_to_cell([old.x, old.y]))]
    sim.step_action(12)
    g = sim.grid
    assert not g.occupied[tuple(g.world_to_cell([old.x, old.y]))]
    assert g.occupied[tuple(g.world_to_cell([5.0, 5.2]))]
    assert sim.lidar()[0] == pytest.approx(6.6 - 1.0, abs=1e-3)  # now sees the east wall
    assert sim.move_to((5.5, 3.0), frame="world").success
    # reset restores the original layout in both the grid and pybullet
    sim.reset(seed=0, start=(1.0, 3.0, 0.0))
    assert sim.layout.shape("central_box") == old
    assert sim.lidar()[0] == pytest.approx(1.7, abs=1e-3)


def test_teleport_is_invisible_to_odometry(make_sim):
    sim = make_sim("house", seed=0)
    odom = sim.odometry()
    sim.teleport((14.5, 1.5, 0.3))
    assert np.array_equal(sim.odometry(), odom)
    assert np.allclose(sim.true_pose(), [14.5, 1.5, 0.3])


def test_panorama_is_deterministic_and_place_specific(make_sim):
    a = make_sim("house", seed=0, start=0)
    b = make_sim("house", seed=0, start=0)
    pa, pb = a.panorama(), b.panorama()
    assert pa.shape == (64, 256, 3) and pa.dtype == np.uint8
    assert np.array_equal(pa, pb)
    a.teleport(a.layout.starts[3])
    other = a.panorama()
    assert np.abs(other.astype(int) - pa.astype(int)).mean() > 5
    # aligned to the odometry frame: turning in place does not change the panorama
    b.teleport((*b.true_pose()[:2], 1.0))
    b.odom.pose[2] = 1.0
    assert np.abs(b.panorama().astype(int) - pb.astype(int)).mean() < 1.0

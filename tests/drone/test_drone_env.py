"""The pybullet obstacle field, the drone's flight and LiDAR, the Gymnasium id, the PNGs."""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import cogmap.envs  # noqa: F401  (registers the ids)
from cogmap.envs.drone_field import make_field
from cogmap.envs.drone_sim import DroneConfig, DroneSim
from cogmap.envs.registry import DRONE_ID


def free_face(field, gap):
    """A tall block and a point ``gap`` m in front of its +x face with nothing nearer (z = 3.5 m)."""
    for b in field.blocks:
        if b.sz < 5:
            continue
        pos = np.array([b.x + b.sx / 2 + gap, b.y, 3.5])
        ahead = pos + np.array([3.0, 0, 0])
        if field.distance(pos)[0] >= min(gap, 3.5) - 1e-9 and field.distance(ahead)[0] >= 3.0:
            return b, pos
    raise AssertionError("no free block face")


@pytest.fixture(scope="module")
def sim():
    s = DroneSim(0)
    yield s
    s.close()


def test_field_is_seeded_and_has_every_kind():
    a, b, c = make_field(0), make_field(0), make_field(1)
    assert a == b and a != c
    kinds = {blk.kind for blk in a.blocks}
    assert kinds == {"house", "alley"} and len(a.trunks) == len(a.crowns) > 100
    lo, hi = a.bounds3()
    assert lo[:, :2].min() > -110 and hi[:, :2].max() < 110
    assert a.distance([a.start])[0] > 2.0  # the start is in a clear zone


def test_targets_are_valid(sim):
    rng = np.random.default_rng(0)
    s = np.array(sim.field.start)
    for _ in range(20):
        t = sim.sample_target(rng)
        assert 15.0 <= np.hypot(*(t - s)[:2]) <= 100.0 and 2.0 <= t[2] <= 20.0
        assert sim.field.distance(t)[0] >= 1.5 and sim.target_free(t)
    inside = sim.field.blocks[0]
    assert not sim.target_free([inside.x, inside.y, inside.z])


def test_contact_agrees_with_exact_geometry(sim):
    pts = np.random.default_rng(1).uniform([-100, -100, 0], [100, 100, 14], (600, 3))
    d = sim.field.distance(pts)
    contact = np.array([sim.contact(q) for q in pts])
    clear_cut = np.abs(d - sim.config.radius) > 1e-3
    assert (contact[clear_cut] == (d[clear_cut] <= sim.config.radius)).all()
    assert contact.sum() > 20


def test_lidar_shape_range_and_hits(sim):
    b, pos = free_face(sim.field, 3.0)
    scan = sim.scan(pos)
    assert scan.directions.shape == (400, 3) and scan.ranges.shape == (400,)
    el = np.degrees(np.arcsin(scan.directions[:, 2]))
    assert el.min() == pytest.approx(-10) and el.max() == pytest.approx(10)
    assert 3.0 - 1e-6 <= scan.min_range <= 3.0 / np.cos(np.radians(7.2 + 1.4))  # the wall 3 m away
    assert (np.linalg.norm(scan.points - pos, axis=1) <= 20.0 + 1e-6).all()
    low = sim.scan(np.array([0.0, 0.0, 1.0]))  # from 1 m the -10 deg rays reach the ground at 5.7 m
    assert len(low.ground) >= 25 and np.allclose(low.ground[:, 2], 0.0, atol=1e-6)


def _wall_flight(end_on_collision):
    s = DroneSim(0, DroneConfig(end_on_collision=end_on_collision))
    try:
        b, start = free_face(s.field, 4.0)
        s.reset(start)
        f = s.fly_to(start + [-8.0, 0, 0], 2.0)
        return s, f, b
    finally:
        s.close()


def test_collision_counted_and_episode_continues_unless_switched():
    s, f, b = _wall_flight(False)
    assert f.collided and not f.reached and s.collisions == 1 and not s.crashed
    assert f.end[0] == pytest.approx(b.x + b.sx / 2 + 0.25, abs=0.11)  # stopped at the last free position
    assert f.duration == pytest.approx(4.0 / 2.0, abs=0.15)  # ~3.75 m at 2 m/s, dt 0.05
    s2, f2, _ = _wall_flight(True)
    assert f2.collided and s2.crashed


def test_replan_when_obstacle_comes_within_2m(sim):
    b, start = free_face(sim.field, 6.0)
    sim.reset(start)
    f = sim.fly_to(start + [-5.0, 0, 0], 2.0, replan_distance=2.0)
    gap = f.end[0] - (b.x + b.sx / 2)
    assert f.replanned and not f.collided and 1.5 - 1e-6 <= gap < 2.0  # scans every 0.25 s = 0.5 m


def test_gym_check_env_and_determinism():
    env = gym.make(DRONE_ID, render_mode="rgb_array")
    try:
        check_env(env.unwrapped)
        o1, _ = env.reset(seed=4)
        o2, _ = env.reset(seed=4)
        assert np.array_equal(o1["target"], o2["target"])
        obs, r, term, trunc, info = env.step(np.array([0.2, 0.2, 0.0], np.float32))
        assert obs["lidar"].shape == (400,) and np.isfinite(r) and info["time"] > 0
        img = env.unwrapped.render()
        assert img.shape == (256, 256, 3) and img.dtype == np.uint8
    finally:
        env.close()


def test_flight_pngs(tmp_path, sim):
    from cogmap.envs.drone_render import save_flight_pngs

    sim.reset()
    sim.fly_to(np.array(sim.field.start) + [5.0, 3.0, 2.0])
    top, side = save_flight_pngs(sim.field, np.array(sim.path), [30.0, 20.0, 8.0], tmp_path)
    for f in (top, side):
        with open(f, "rb") as fh:
            assert fh.read(8) == b"\x89PNG\r\n\x1a\n"

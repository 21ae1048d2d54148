"""Panoramas must be alike for nearby places and unlike for distant ones under the
agent's SSIM (threshold 0.65), so observation ids can identify places."""

import numpy as np
import pytest

from cogmap.agent.encoder import ssim
from cogmap.envs.places import displaced_pairs, distant_pairs, panorama_at
from cogmap.envs.sim import NavSim

LAYOUTS = ("mini_warehouse", "small_warehouse", "house")
N = 16


def _median(sim, pairs):
    return float(np.median([ssim(panorama_at(sim, a), panorama_at(sim, b)) for a, b in pairs]))


@pytest.fixture(scope="module", params=LAYOUTS)
def stats(request):
    sim = NavSim(request.param, seed=0, start=0)
    rng = np.random.default_rng(7)
    try:
        out = {dx: _median(sim, displaced_pairs(sim, dx, N, rng)) for dx in (0.1, 0.25, 1.0, 2.0)}
        out["far"] = _median(sim, distant_pairs(sim, 3.0, 2 * N, rng))
    finally:
        sim.close()
    return request.param, out


def test_nearby_places_match(stats):
    name, s = stats
    assert s[0.1] >= 0.7 and s[0.25] >= 0.7, (name, s)


def test_places_a_metre_apart_differ(stats):
    name, s = stats
    assert s[1.0] < 0.6 and s[2.0] < 0.6, (name, s)


def test_distant_places_differ(stats):
    name, s = stats
    assert s["far"] < 0.5, (name, s)


def test_similarity_decreases_with_distance(stats):
    name, s = stats
    assert s[0.1] > s[0.25] > s[1.0] >= s["far"] - 0.05, (name, s)


def test_turning_in_place_with_odometry_keeps_the_panorama(make_sim):
    """The robot turns, odometry measures the turn: the odometry-aligned panorama is the
    same picture."""
    sim = make_sim("small_warehouse", seed=0, start=0)
    before = sim.panorama()
    x, y, yaw = sim.true_pose()
    sim.teleport((x, y, yaw + 1.0))
    sim.odom.rotate(1.0)
    assert ssim(sim.panorama(), before) > 0.95


def test_textures_are_deterministic_and_distinct():
    from cogmap.envs.layouts import make_layout
    from cogmap.envs.textures import layout_floor_texture, shape_texture

    lay = make_layout("house")
    walls = [s for s in lay.shapes if s.name.startswith("wall")]
    a = [shape_texture(lay.name, s) for s in walls]
    b = [shape_texture(lay.name, s) for s in walls]
    assert all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))
    assert all(t.dtype == np.uint8 and t.std() > 10 for t in a)
    # different wall segments get different patterns
    assert len({t.tobytes() for t in a}) == len(a)
    floor = layout_floor_texture(lay.name, (18.0, 13.0), (0.55, 0.55, 0.5))
    assert floor.shape == (208, 288, 3) and floor.std() > 5


def test_png_writer_round_trips(tmp_path):
    import matplotlib.image as mpimg

    from cogmap.envs.textures import write_png

    img = np.random.default_rng(0).integers(0, 256, (5, 7, 3), dtype=np.uint8)
    write_png(tmp_path / "t.png", img)
    back = (mpimg.imread(tmp_path / "t.png")[..., :3] * 255).round().astype(np.uint8)
    assert np.array_equal(back, img)

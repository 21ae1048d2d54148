import numpy as np
import pytest

from cogmap.envs.geometry import ShapeSet
from cogmap.envs.layouts import LAYOUTS, make_layout, random_rooms
from cogmap.envs.occupancy import layout_grid, rasterise
from cogmap.envs.robot import ROBOT_RADIUS

PAPER = {"mini_warehouse": 36, "small_warehouse": 80, "large_warehouse": 280, "house": 175,
         "bedroom": 20.3, "parking_lot": 325, "aisle_warehouse": 185}


@pytest.mark.parametrize("name", sorted(PAPER))
@pytest.mark.parametrize("seed", [0, 3])
def test_free_area_matches_paper(name, seed):
    lay = make_layout(name, seed)
    area = layout_grid(lay).free_area(lay.starts[0][:2])
    assert lay.paper_area == pytest.approx(PAPER[name])
    assert abs(area - PAPER[name]) <= 0.10 * PAPER[name], area


@pytest.mark.parametrize("name", sorted(LAYOUTS))
def test_starts_are_free_and_connected(name):
    lay = make_layout(name, 1)
    grid = layout_grid(lay)
    reach = grid.reachable(lay.starts[0][:2])
    starts = np.array([s[:2] for s in lay.starts])
    assert (ShapeSet(lay.shapes).distance(starts) > ROBOT_RADIUS + 0.1).all()
    rc = grid.world_to_cell(starts)
    assert reach[rc[:, 0], rc[:, 1]].all()
    assert len(set(lay.names)) == len(lay.names)


def test_grid_geometry_and_reachability():
    lay = make_layout("mini_warehouse")
    g = layout_grid(lay, 0.05)
    box = lay.shape("central_box")
    assert g.occupied[tuple(g.world_to_cell([box.x, box.y]))]
    assert not g.occupied[tuple(g.world_to_cell([1.0, 1.0]))]
    # the box footprint (1.2 m square) covers about 24 x 24 cells, grown by up to one cell
    r0, c0 = g.world_to_cell([box.x - 1.0, box.y - 1.0])
    r1, c1 = g.world_to_cell([box.x + 1.0, box.y + 1.0])
    n = g.occupied[r0:r1, c0:c1].sum()
    assert 24 * 24 <= n <= 26 * 26
    # with a margin around the enclosure, the outside is free but not reachable
    xmin, ymin, xmax, ymax = lay.bounds
    big = rasterise(lay.shapes, (xmin - 1, ymin - 1, xmax + 1, ymax + 1))
    assert big.free_area([1.0, 1.0]) == pytest.approx(g.free_area([1.0, 1.0]))
    assert not big.reachable([1.0, 1.0])[tuple(big.world_to_cell([xmin - 0.5, 0.0]))]
    assert np.allclose(g.cell_to_world(g.world_to_cell([1.02, 2.04])), [1.025, 2.025])


def test_layouts_are_seeded():
    a, b, c = random_rooms(5), random_rooms(5), random_rooms(6)
    assert a == b and a != c
    p0, p1 = make_layout("parking_lot", 0), make_layout("parking_lot", 1)
    assert p0 == make_layout("parking_lot", 0) and p0 != p1


@pytest.mark.parametrize("seed", range(6))
def test_random_rooms_connected(seed):
    lay = random_rooms(seed, n_x=3, n_y=3)
    reach = layout_grid(lay).reachable(lay.starts[0][:2])
    g = layout_grid(lay)
    for s in lay.starts:
        assert reach[tuple(g.world_to_cell(s[:2]))], s


def test_with_moved_changes_only_that_shape():
    lay = make_layout("mini_warehouse")
    moved = lay.with_moved("central_box", (1.5, 4.5))
    assert moved.shape("central_box").x == 1.5 and lay.shape("central_box").x == 3.3
    assert [s for s in moved.shapes if s.name != "central_box"] == [
        s for s in lay.shapes if s.name != "central_box"]
    with pytest.raises(KeyError):
        lay.with_moved("nope", (0, 0))

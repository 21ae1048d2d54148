"""Openings between rooms and warehouse aisles are >= 1.6 m wide.

A lattice agent (nodes ~1 m apart, 12 headings) crosses an opening off-centre; with the
robot's 0.32 m corridor half-width a 1.6 m opening admits paths within +-0.48 m of its
centre. Checked by flood fill over cells whose clearance exceeds 0.77 m (half of 1.6 m,
less half a 5 cm cell for discretisation): from every probe point (starts, room centres,
aisles), a straight robot-wide corridor must lead to a cell of the first start's
component of such cells, i.e. the probe is reached without any passage under 1.6 m.
"""

import numpy as np
import pytest
from scipy import ndimage

from cogmap.envs.geometry import ShapeSet
from cogmap.envs.layouts import LAYOUTS, OPENING, make_layout, random_rooms
from cogmap.envs.occupancy import layout_grid

HALF = 0.77

# probe points per layout besides the starts: one per room / aisle / strip
PROBES = {
    "house": [(2.0, 3.0), (9.5, 10.8), (14.2, 7.6), (3.0, 11.0), (15.5, 3.5)],
    "small_warehouse": [(5.2, 4.4), (5.2, 1.3), (5.2, 7.5)],
    "large_warehouse": [(11.0, 1.4), (11.0, 4.95), (11.0, 8.25), (11.0, 11.55),
                        (13.0, 14.95), (20.0, 12.0)],
    "aisle_warehouse": [(7.5, 0.8), (7.5, 3.75), (7.5, 7.05), (7.5, 10.6), (0.8, 5.4)],
    "mini_warehouse": [(1.2, 3.0), (5.5, 3.0)],
}


CORRIDOR = 0.32  # robot radius 0.22 + 0.1 margin


def wide_component(lay):
    grid = layout_grid(lay)
    rows, cols = np.indices(grid.shape)
    xy = grid.cell_to_world(np.stack([rows.ravel(), cols.ravel()], 1))
    clear = ShapeSet(lay.shapes).distance(xy).reshape(grid.shape) > HALF
    labels, _ = ndimage.label(clear)
    start = grid.world_to_cell(lay.starts[0][:2])
    # the start may sit closer than 0.77 m to furniture: use the nearest wide cell
    cells = np.argwhere(clear)
    near = cells[np.argmin(((cells - start) ** 2).sum(1))]
    comp = labels == labels[tuple(near)]
    return grid, grid.cell_to_world(np.argwhere(comp))


def assert_connected(lay, points):
    grid, comp_xy = wide_component(lay)
    shapes = ShapeSet(lay.shapes)
    bad = []
    for p in np.asarray(points, float):
        order = np.argsort(((comp_xy - p) ** 2).sum(1))[:400:20]  # nearest wide cells
        ok = False
        for q in comp_xy[order]:
            seg = p + np.linspace(0, 1, 30)[:, None] * (q - p)
            if (shapes.distance(seg) > CORRIDOR).all():
                ok = True
                break
        if not ok:
            bad.append(tuple(p))
    assert not bad, f"{lay.name}: not connected through >= 1.6 m passages: {bad}"


@pytest.mark.parametrize("name", sorted(PROBES))
@pytest.mark.parametrize("seed", [0, 3])
def test_rooms_and_aisles_are_wide(name, seed):
    lay = make_layout(name, seed)
    assert_connected(lay, [s[:2] for s in lay.starts] + PROBES[name])


@pytest.mark.parametrize("seed", range(4))
def test_random_rooms_doors_are_wide(seed):
    lay = random_rooms(seed, n_x=3, n_y=3)
    assert_connected(lay, [s[:2] for s in lay.starts])


def test_house_openings_are_the_set_width():
    lay = make_layout("house")
    walls = [s for s in lay.shapes if s.name.startswith("wall")]
    # collinear interior wall pieces: gaps between consecutive pieces are the openings
    gaps = []
    for axis in (0, 1):
        lines = {}
        for s in walls:
            thin = s.sy if axis == 0 else s.sx
            if thin < 0.14:  # interior walls are 0.12 m thick
                key = round(s.y if axis == 0 else s.x, 3)
                span = ((s.x - s.sx / 2, s.x + s.sx / 2) if axis == 0 else
                        (s.y - s.sy / 2, s.y + s.sy / 2))
                lines.setdefault(key, []).append(span)
        for spans in lines.values():
            spans.sort()
            gaps += [b[0] - a[1] for a, b in zip(spans, spans[1:], strict=False)]
    assert len(gaps) >= 4
    assert all(g == pytest.approx(OPENING) for g in gaps), gaps
    assert OPENING >= 1.6
    assert len(LAYOUTS) >= 8

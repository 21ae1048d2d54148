"""Your own building: JSON layouts and PNG plans load, validate with one-line errors, round trip."""

from __future__ import annotations

import copy
import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

from cogmap.envs.layout_file import (
    LayoutFileError,
    layout_from_dict,
    layout_to_json,
    load_layout,
)
from cogmap.envs.layouts import LAYOUTS, make_layout
from cogmap.envs.occupancy import layout_grid

EXAMPLE = Path(__file__).resolve().parents[2] / "docs" / "examples" / "building.json"


def _room(**extra) -> dict:
    """A 6 x 4 m room with a door-less partition and one table."""
    d = {"name": "room", "walls": [{"from": [0, 0], "to": [6, 0]}, {"from": [6, 0], "to": [6, 4]},
                                   {"from": [6, 4], "to": [0, 4]}, {"from": [0, 4], "to": [0, 0]},
                                   {"from": [3, 0], "to": [3, 4], "gaps": [[1.0, 2.6]]}],
         "furniture": [{"type": "box", "x": 1.0, "y": 3.3, "size": [1.0, 0.6]}],
         "starts": [[1.0, 1.0, 0.0], [5.0, 2.0, 3.14]]}
    d.update(extra)
    return d


@pytest.mark.parametrize("name", sorted(LAYOUTS))
def test_every_shipped_layout_round_trips_through_json(name):
    lay = make_layout(name, seed=3)
    back = layout_from_dict(json.loads(layout_to_json(lay)))
    assert back == dataclasses.replace(lay, paper_area=None)


def test_the_example_building_loads_with_its_starts_and_area(tmp_path):
    lay = load_layout(EXAMPLE)
    assert lay.name == "l_corridor" and lay.texture_seed == 0 and len(lay.starts) == 3
    area = layout_grid(lay).free_area(lay.starts[0][:2])
    assert 70 < area < 90  # corridor 38 m2 + rooms 18, 22 and 12 m2, less walls and furniture
    assert lay.shape("crate").movable and not lay.shape("desk").movable
    # a door gap splits its wall: the corridor wall with two doors is three boxes
    walls = [s for s in lay.shapes if s.name.startswith("wall")]
    assert len(walls) == 10 + 2 + 1
    layout_to_json(lay, tmp_path / "again.json")
    assert load_layout(tmp_path / "again.json") == lay


def test_starts_are_sampled_in_the_largest_free_region_when_not_given():
    d = _room()
    del d["starts"]
    lay = layout_from_dict(d)
    xy = np.array([s[:2] for s in lay.starts])
    assert len(xy) == 5
    d = np.hypot(*(xy[:, None] - xy[None]).transpose(2, 0, 1))
    assert d[np.triu_indices(5, 1)].min() >= 1.0  # distinct
    grid = layout_grid(lay)
    assert all(grid.clearance()[tuple(grid.world_to_cell(p))] >= 0.27 for p in xy)  # free with room for the robot
    reach = grid.reachable(xy[0])
    assert all(reach[tuple(grid.world_to_cell(p))] for p in xy)  # all in one connected region


def test_a_png_plan_loads_with_its_scale(tmp_path):
    import cv2

    img = np.full((80, 120), 255, np.uint8)  # 6 x 4 m at 0.05 m per pixel
    img[:, 58:62] = 0  # a partition at x = 3 m with a 1.6 m door in the middle
    img[24:56, 58:62] = 255
    cv2.imwrite(str(tmp_path / "plan.png"), img)
    lay = load_layout(tmp_path / "plan.png")
    assert lay.bounds == pytest.approx((-0.15, -0.15, 6.15, 4.15))
    grid = layout_grid(lay)
    assert 20 < grid.free_area(lay.starts[0][:2]) < 24  # 24 m2 less the partition
    assert len(lay.starts) == 5
    # the partition is where the image says: x 2.9 - 3.1 m, solid at y = 0.5 m, open at y = 2 m
    assert grid.occupied[tuple(grid.world_to_cell([3.0, 0.5]))]
    assert not grid.occupied[tuple(grid.world_to_cell([3.0, 2.0]))]
    half = tmp_path / "half.json"
    half.write_text(json.dumps({"name": "half", "image": "plan.png", "metres_per_pixel": 0.025}))
    assert load_layout(half).bounds == pytest.approx((-0.15, -0.15, 3.15, 2.15))


def _edit(path, value):
    def edit(d):
        *head, last = path
        node = d
        for k in head:
            node = node[k]
        if value is KeyError:
            del node[last]
        else:
            node[last] = value
    return edit


#: (what, edit of the valid room, expected message ending)
BAD_JSON = [
    ("missing key", _edit(["walls", 1, "to"], KeyError), "walls[1]: missing key 'to'"),
    ("unknown key", _edit(["furniture", 0, "colour"], [1, 0, 0]), "furniture[0]: unknown key 'colour'"),
    ("non-numeric size", _edit(["furniture", 0, "size"], ["wide", 1]),
     "furniture[0].size[0]: expected a number, got \"wide\""),
    ("negative size", _edit(["walls", 0, "thickness"], -0.1), "walls[0].thickness: must be positive, got -0.1"),
    ("NaN size", _edit(["furniture", 0, "height"], float("nan")), "furniture[0].height: must be finite, got nan"),
    ("zero-length wall", _edit(["walls", 2, "to"], [6, 4]),
     "walls[2]: zero length (from and to are both [6.0, 4.0])"),
    ("gap outside its wall", _edit(["walls", 4, "gaps"], [[3.0, 5.0]]),
     "walls[4].gaps[0]: expected 0 <= start < end <= 4 (the wall's length), got [3.0, 5.0]"),
    ("start outside the bounds", _edit(["starts", 1], [7.0, 2.0, 0.0]),
     "starts[1]: (7, 2) lies outside the bounds"),
    ("start inside an obstacle", _edit(["starts", 1], [1.0, 3.3, 0.0]),
     "starts[1]: (1, 3.3) lies inside an obstacle"),
    ("start where the robot does not fit", _edit(["starts", 1], [5.85, 2.0, 0.0]),
     "starts[1]: (5.85, 2) is closer than 0.27 m to an obstacle (the robot does not fit)"),
    ("disconnected starts", _edit(["walls", 4, "gaps"], []),
     "starts[1]: [5.0, 2.0] cannot be reached from starts[0] [1.0, 1.0] (no passage wide enough for the robot)"),
    ("building open to the outside", _edit(["walls", 1, "gaps"], [[1.0, 3.0]]),
     "walls: the free space around the starts reaches the bounds: close the building with walls"),
    ("no free space", lambda d: d.update(walls=[{"from": [0, 0], "to": [0.3, 0]}, {"from": [0.3, 0], "to": [0.3, 0.3]},
                                                {"from": [0.3, 0.3], "to": [0, 0.3]},
                                                {"from": [0, 0.3], "to": [0, 0]}], furniture=[], starts=None),
     "no free space: nowhere can a robot of radius 0.22 m stand clear of the walls"),
    ("furniture of unknown type", _edit(["furniture", 0, "type"], "sofa"),
     "furniture[0].type: expected \"box\" or \"cylinder\", got \"sofa\""),
    # sizes are bounded before the validation grid is allocated (a 5 km square used to hang there)
    ("walls enclosing a 5 km square", lambda d: d.update(walls=_square(5000.0), furniture=[], starts=None),
     "walls: the building spans 5000.15 x 5000.15 m, above the limit of 100 m on a side (MAX_EXTENT_M)"),
    ("a 3 km room", lambda d: d.update(walls=_square(3000.0), furniture=[], starts=None),
     "walls: the building spans 3000.15 x 3000.15 m, above the limit of 100 m on a side (MAX_EXTENT_M)"),
    ("bounds of 20,000 km", lambda d: d.update(bounds=[-1e7, -1e7, 1e7, 1e7]),
     "bounds[0]: -1e+07 m, beyond the limit of +-10000 m (MAX_COORDINATE_M)"),
    ("bounds of 2 km", lambda d: d.update(bounds=[-1e3, -1e3, 1e3, 1e3]),
     "bounds: the building spans 2000 x 2000 m, above the limit of 100 m on a side (MAX_EXTENT_M)"),
    ("a table 1 km wide", _edit(["furniture", 0, "size"], [1000.0, 1.0]),
     "furniture[0].size[0]: 1000 m, above the limit of 100 m (MAX_EXTENT_M)"),
]


def _square(side: float) -> list:
    return [{"from": [0, 0], "to": [side, 0]}, {"from": [side, 0], "to": [side, side]},
            {"from": [side, side], "to": [0, side]}, {"from": [0, side], "to": [0, 0]}]


@pytest.mark.parametrize("what, edit, message", BAD_JSON, ids=[c[0] for c in BAD_JSON])
def test_bad_json_layouts_are_refused_naming_the_entry(what, edit, message):
    d = copy.deepcopy(_room())
    edit(d)
    with pytest.raises(LayoutFileError) as err:
        layout_from_dict(d, "b.json")
    assert str(err.value).startswith("b.json: ") and message in str(err.value) and "\n" not in str(err.value)


def test_bad_files_are_refused_before_reading(tmp_path):
    (tmp_path / "dir.json").mkdir()
    with pytest.raises(LayoutFileError, match="dir.json: not a regular file"):
        load_layout(tmp_path / "dir.json")
    (tmp_path / "bad.json").write_text("{'name': 1}")
    with pytest.raises(LayoutFileError, match=r"bad.json: invalid JSON \(Expecting property name"):
        load_layout(tmp_path / "bad.json")
    # a PNG header claiming 100000 x 100000 pixels: refused from the header, nothing decoded
    header = b"\x89PNG\r\n\x1a\n" + b"\x00\x00\x00\x0dIHDR" + (100000).to_bytes(4, "big") * 2 + b"\x08\x00\x00\x00\x00"
    (tmp_path / "huge.png").write_bytes(header)
    with pytest.raises(LayoutFileError, match="huge.png: 100000 x 100000 pixels, outside 1 .. 16777216"):
        load_layout(tmp_path / "huge.png")
    (tmp_path / "text.png").write_text("not an image")
    with pytest.raises(LayoutFileError, match="text.png: not a PNG image"):
        load_layout(tmp_path / "text.png")


def test_a_small_plan_at_a_huge_scale_is_refused_before_allocating(tmp_path):
    import cv2

    from cogmap.envs.layout_file import MAX_EXTENT_M, MAX_GRID_CELLS, check_extent

    img = np.full((20, 20), 255, np.uint8)
    cv2.imwrite(str(tmp_path / "plan.png"), img)
    (tmp_path / "plan.json").write_text(json.dumps({"name": "p", "image": "plan.png", "metres_per_pixel": 1e5}))
    with pytest.raises(LayoutFileError, match=r"plan.png: 20 x 20 pixels at metres_per_pixel 100000: the building "
                                              r"spans 2e\+06 x 2e\+06 m, above the limit of 100 m on a side"):
        load_layout(tmp_path / "plan.json")
    with pytest.raises(LayoutFileError, match="above the limit of 100 m"):
        load_layout(tmp_path / "plan.png", metres_per_pixel=1e5)
    # the grid bound: the limits agree at the validation resolution
    check_extent((0.0, 0.0, MAX_EXTENT_M, MAX_EXTENT_M))
    assert (MAX_EXTENT_M / 0.05) ** 2 <= MAX_GRID_CELLS


def test_a_building_at_the_size_limit_is_validated():
    lay = layout_from_dict({"name": "hall", "walls": _square(99.5)})
    assert lay.bounds == pytest.approx((-0.075, -0.075, 99.575, 99.575)) and len(lay.starts) == 5


@pytest.mark.parametrize("kind", ["corridor", "office", "L", "T", "U", "hall"])
def test_every_procedural_building_is_within_the_limits(kind):
    for seed in range(4):
        lay = make_layout("building", seed, kind=kind)
        back = layout_from_dict(json.loads(layout_to_json(lay)))
        assert back.bounds == lay.bounds


def test_cogmap_explore_runs_in_a_json_building(tmp_path, capsys):
    from cogmap.cli import main

    out = tmp_path / "run"
    assert main(["explore", "--env", str(EXAMPLE), "--steps", "4", "--patience", "0", "--out", str(out), "--quiet",
                 "--time-limit", "0"]) == 0
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["steps"] == 4 and metrics["distance_m"] > 0 and 70 < metrics["free_area_m2"] < 90
    assert json.loads((out / "run.json").read_text())["env"] == str(EXAMPLE)


def test_before_a_run_the_file_is_read_and_bounded_and_the_building_is_validated_in_the_run(tmp_path, capsys,
                                                                                             monkeypatch):
    """``cogmap explore`` checks a layout file quickly in the parent (every entry read and bounded,
    nothing rasterised); the free-space checks run in the supervised child, under --time-limit,
    before the run writes anything."""
    from cogmap import explore as explore_mod
    from cogmap.cli import main
    from cogmap.envs import layout_file

    d = _room()
    d["walls"][1]["gaps"] = [[1.0, 3.0]]  # open to the outside: only the free-space check sees it
    path = tmp_path / "open.json"
    path.write_text(json.dumps(d))
    huge = tmp_path / "huge.json"
    huge.write_text(json.dumps({"name": "huge", "walls": _square(5000.0)}))
    with monkeypatch.context() as m:
        m.setattr(layout_file, "layout_grid", lambda *a, **k: pytest.fail("rasterised before the run"))
        explore_mod.check_env(str(path))
        with pytest.raises(LayoutFileError, match="above the limit of 100 m on a side"):
            explore_mod.check_env(str(huge))
    out = tmp_path / "run"
    code = main(["explore", "--env", str(path), "--out", str(out), "--quiet", "--time-limit", "120"])
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert code == 2 and err.startswith("cogmap explore: error: ") and "close the building with walls" in err
    assert not out.exists() or not any(out.iterdir())  # refused before run.json or anything else

"""Your own building: a layout declared in a JSON file or drawn as an occupancy image.

JSON (every length in metres, angles in radians; optional keys in brackets)::

    {"name": "my_office",
     ["bounds": [xmin, ymin, xmax, ymax]],        # default: the walls' extent
     "walls": [{"from": [x0, y0], "to": [x1, y1],
                ["thickness": 0.15], ["height": 2.0], ["color": [r, g, b]],
                ["gaps": [[a, b], ...]]}],        # door openings, metres along the wall from "from"
     ["furniture": [{"type": "box", "x": .., "y": .., "size": [sx, sy], ["height": 1.0], ["yaw": 0],
                     ["color": [r, g, b]], ["movable": false], ["name": "desk"]},
                    {"type": "cylinder", "x": .., "y": .., "radius": .., ...}]],
     ["starts": [[x, y, yaw], ...]],              # default: sampled in the largest free region
     ["texture_seed": 0],                         # another seed gives other wall and floor patterns
     ["image": "plan.png", "metres_per_pixel": 0.05]}   # walls from an occupancy image instead

An occupancy image (PNG, greyscale or colour) is read with dark pixels (< 128) as walls and
``metres_per_pixel`` as its scale (default :data:`DEFAULT_METRES_PER_PIXEL`); its pixel (0, 0) is the
top-left corner, so row r lies at y = (height - r - 1) * scale. Outer walls are added around it.

Every problem is a :class:`LayoutFileError` (a ``ValueError``) naming the file, the entry and the
problem: missing or unknown keys, non-numeric, non-finite or non-positive sizes, walls of zero
length, gaps outside their wall, duplicate names, starts outside the bounds or where the robot does
not fit, no free space, starts that cannot reach each other, free space open to the outside, files
that are not regular files or are too large, images with too many pixels (checked from the PNG
header before decoding), buildings larger than :data:`MAX_EXTENT_M` on a side or whose validation
grid would exceed :data:`MAX_GRID_CELLS` cells (checked from the bounds, the walls' extent or the
image size times ``metres_per_pixel``, before any grid is allocated).
"""

from __future__ import annotations

import json
import math
import struct
from pathlib import Path

import numpy as np
from scipy import ndimage

from cogmap.genmodel.files import regular_file_size

from .geometry import Box, Cylinder
from .layout_builder import WALL, WALL_H, Builder, Layout, wall_segments
from .occupancy import layout_grid
from .robot import ROBOT_RADIUS

FORMAT = "cogmap-layout"
MAX_FILE_BYTES = 10 * 2**20  # a JSON building or a PNG plan
MAX_IMAGE_PIXELS = 4096 * 4096
MAX_SHAPES = 5000
DEFAULT_METRES_PER_PIXEL = 0.05
NUM_SAMPLED_STARTS = 5
START_CLEARANCE = ROBOT_RADIUS + 0.05  # a start needs this much room around the robot's centre
GRID_RESOLUTION = 0.05
#: largest side of a building, metres (its bounds, or the walls' and furniture's extent, or a plan's
#: pixels times ``metres_per_pixel``); every built-in layout and procedural building is under 40 m
MAX_EXTENT_M = 100.0
#: largest validation grid (cells of :data:`GRID_RESOLUTION` over the bounds), checked before it is
#: allocated: a 100 m square at 0.05 m, validated in about 1 s with about 0.35 GB at peak
MAX_GRID_CELLS = 4_000_000
#: largest |coordinate| of a wall end, a piece of furniture, a bound or a start, metres
MAX_COORDINATE_M = 10_000.0

_TOP = {"format", "name", "bounds", "walls", "furniture", "starts", "texture_seed", "image", "metres_per_pixel"}
_WALL = {"from", "to", "thickness", "height", "color", "gaps"}
_BOX = {"type", "name", "x", "y", "size", "height", "yaw", "color", "movable"}
_CYL = {"type", "name", "x", "y", "radius", "height", "color", "movable"}


class LayoutFileError(ValueError):
    """A layout file that cannot be used; the message names the file, the entry and the problem."""


# -- reading values ----------------------------------------------------------------------------------
class _Reader:
    def __init__(self, source: str):
        self.source = source

    def fail(self, where: str, problem: str):
        raise LayoutFileError(f"{self.source}: {where}: {problem}" if where else f"{self.source}: {problem}")

    def keys(self, d, where: str, allowed: set, required: tuple = ()) -> dict:
        if not isinstance(d, dict):
            self.fail(where, f"expected an object, got {type(d).__name__}")
        for k in required:
            if k not in d:
                self.fail(where, f"missing key {k!r}")
        unknown = sorted(set(d) - allowed)
        if unknown:
            self.fail(where, f"unknown key {unknown[0]!r} (known: {', '.join(sorted(allowed))})")
        return d

    def number(self, v, where: str, positive: bool = False, nonnegative: bool = False,
               size: bool = False, coordinate: bool = False) -> float:
        if isinstance(v, bool) or not isinstance(v, int | float):
            self.fail(where, f"expected a number, got {json.dumps(v)}")
        v = float(v)
        if not math.isfinite(v):
            self.fail(where, f"must be finite, got {v}")
        if positive and v <= 0:
            self.fail(where, f"must be positive, got {v:g}")
        if nonnegative and v < 0:
            self.fail(where, f"must not be negative, got {v:g}")
        if size and v > MAX_EXTENT_M:
            self.fail(where, f"{v:g} m, above the limit of {MAX_EXTENT_M:g} m (MAX_EXTENT_M)")
        if coordinate and abs(v) > MAX_COORDINATE_M:
            self.fail(where, f"{v:g} m, beyond the limit of +-{MAX_COORDINATE_M:g} m (MAX_COORDINATE_M)")
        return v

    def vector(self, v, where: str, n: int, **kw) -> tuple[float, ...]:
        if not isinstance(v, list | tuple) or len(v) != n:
            self.fail(where, f"expected a list of {n} numbers, got {json.dumps(v)}")
        return tuple(self.number(x, f"{where}[{i}]", **kw) for i, x in enumerate(v))

    def color(self, v, where: str):
        c = self.vector(v, where, 3, nonnegative=True)
        if max(c) > 1:
            self.fail(where, f"colour components must lie in [0, 1], got {list(c)}")
        return c

    def flag(self, v, where: str) -> bool:
        if not isinstance(v, bool):
            self.fail(where, f"expected true or false, got {json.dumps(v)}")
        return v

    def name(self, v, where: str) -> str:
        if not isinstance(v, str) or not v.strip():
            self.fail(where, f"expected a non-empty string, got {json.dumps(v)}")
        return v


def check_extent(bounds, source: str = "layout", where: str = "bounds") -> None:
    """Refuse a building larger than :data:`MAX_EXTENT_M` on a side, or whose validation grid would
    have more than :data:`MAX_GRID_CELLS` cells, before any grid is allocated.

    Parameters
    ----------
    bounds : sequence of float
        ``(xmin, ymin, xmax, ymax)`` in metres.
    source : str, optional
        The file, for the message.
    where : str, optional
        The entry the extent comes from (``bounds``, ``walls``, ``image``), for the message.

    Raises
    ------
    LayoutFileError
        Naming the entry, the size and the limit.
    """
    xmin, ymin, xmax, ymax = (float(v) for v in bounds)
    w, h = xmax - xmin, ymax - ymin
    if not (math.isfinite(w) and math.isfinite(h)) or max(w, h) > MAX_EXTENT_M:
        raise LayoutFileError(f"{source}: {where}: the building spans {w:.6g} x {h:.6g} m, above the limit of "
                              f"{MAX_EXTENT_M:g} m on a side (MAX_EXTENT_M)")
    cells = math.ceil(w / GRID_RESOLUTION - 1e-9) * math.ceil(h / GRID_RESOLUTION - 1e-9)
    if cells > MAX_GRID_CELLS:
        raise LayoutFileError(f"{source}: {where}: {w:.6g} x {h:.6g} m needs {cells} grid cells of "
                              f"{GRID_RESOLUTION:g} m, above the limit of {MAX_GRID_CELLS} (MAX_GRID_CELLS)")


# -- JSON --------------------------------------------------------------------------------------------
def layout_from_dict(d: dict, source: str = "layout", base_dir: Path | None = None,
                     check_space: bool = True) -> Layout:
    """Build and validate a layout from its JSON description (see the module docstring).

    ``check_space=False`` skips the checks that rasterise the building (free space, starts; see
    :func:`check_layout`): every entry is still read and bounded, quickly."""
    r = _Reader(source)
    r.keys(d, "", _TOP, ("name",))
    if d.get("format", FORMAT) != FORMAT:
        r.fail("format", f"expected {FORMAT!r}, got {json.dumps(d['format'])}")
    name = r.name(d["name"], "name")
    seed = d.get("texture_seed")
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, int) or seed < 0):
        r.fail("texture_seed", f"expected an integer >= 0, got {json.dumps(seed)}")
    b = Builder(0)
    if "image" in d:
        if "walls" in d:
            r.fail("image", "give walls or an image, not both")
        if not isinstance(d["image"], str):
            r.fail("image", f"expected a file name, got {json.dumps(d['image'])}")
        scale = r.number(d.get("metres_per_pixel", DEFAULT_METRES_PER_PIXEL), "metres_per_pixel", positive=True)
        img = Path(d["image"])
        img = img if img.is_absolute() or base_dir is None else base_dir / img
        bounds = _image_walls(b, read_png_mask(img), scale, str(img))
    else:
        if "walls" not in d:
            r.fail("", "missing key 'walls' (or an 'image' to take the walls from)")
        walls = d["walls"]
        if not isinstance(walls, list):
            r.fail("walls", "expected a list of walls")
        for i, w in enumerate(walls):
            _wall(b, r, w, f"walls[{i}]")
        bounds = None
    furniture = d.get("furniture", [])
    if not isinstance(furniture, list):
        r.fail("furniture", "expected a list")
    for i, f in enumerate(furniture):
        _furniture(b, r, f, f"furniture[{i}]")
    if not b.shapes:
        r.fail("walls", "no walls and no furniture")
    if len(b.shapes) > MAX_SHAPES:
        r.fail("", f"{len(b.shapes)} shapes, above the limit of {MAX_SHAPES}")
    names = [s.name for s in b.shapes]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        r.fail("furniture", f"name {dup[0]!r} used twice")
    if "bounds" in d:
        xmin, ymin, xmax, ymax = r.vector(d["bounds"], "bounds", 4, coordinate=True)
        if xmax <= xmin or ymax <= ymin:
            r.fail("bounds", f"expected [xmin, ymin, xmax, ymax] with xmin < xmax and ymin < ymax, got {d['bounds']}")
        bounds = (xmin, ymin, xmax, ymax)
        check_extent(bounds, source, "bounds")
    elif bounds is None:
        bounds = _extent(b.shapes)
        check_extent(bounds, source, "walls")
    starts = d.get("starts")
    if starts is not None:
        if not isinstance(starts, list) or not starts:
            r.fail("starts", "expected a non-empty list of [x, y, yaw]")
        starts = [r.vector(s, f"starts[{i}]", 3, coordinate=True) for i, s in enumerate(starts)]
    layout = Layout(name, tuple(float(v) for v in bounds), tuple(b.shapes), (), None, seed)
    if not check_space:
        return layout if starts is None else _with_starts(layout, starts)
    return check_layout(layout, starts, source)


def _with_starts(layout: Layout, starts) -> Layout:
    import dataclasses

    return dataclasses.replace(layout, starts=tuple(tuple(float(v) for v in s) for s in starts))


def _wall(b: Builder, r: _Reader, w, where: str) -> None:
    r.keys(w, where, _WALL, ("from", "to"))
    x0, y0 = r.vector(w["from"], f"{where}.from", 2, coordinate=True)
    x1, y1 = r.vector(w["to"], f"{where}.to", 2, coordinate=True)
    t = r.number(w.get("thickness", WALL), f"{where}.thickness", positive=True, size=True)
    h = r.number(w.get("height", WALL_H), f"{where}.height", positive=True, size=True)
    color = r.color(w.get("color", (0.8, 0.8, 0.75)), f"{where}.color")
    length = math.hypot(x1 - x0, y1 - y0)
    if length < 1e-6:
        r.fail(where, f"zero length (from and to are both {[x0, y0]})")
    gaps = w.get("gaps", [])
    if not isinstance(gaps, list):
        r.fail(f"{where}.gaps", "expected a list of [start, end] pairs")
    gaps = [r.vector(g, f"{where}.gaps[{i}]", 2, nonnegative=True) for i, g in enumerate(gaps)]
    for i, (a, c) in enumerate(gaps):
        if not a < c <= length + 1e-9:
            r.fail(f"{where}.gaps[{i}]", f"expected 0 <= start < end <= {length:g} (the wall's length), got {[a, c]}")
    ux, uy = (x1 - x0) / length, (y1 - y0) / length
    for a, c in wall_segments(0.0, length, gaps):
        cx, cy = x0 + ux * (a + c) / 2, y0 + uy * (a + c) / 2
        if abs(uy) < 1e-12:
            b.box("wall", cx, cy, c - a, t, h, color)
        elif abs(ux) < 1e-12:
            b.box("wall", cx, cy, t, c - a, h, color)
        else:
            b.box("wall", cx, cy, c - a, t, h, color, yaw=math.atan2(uy, ux))


def _furniture(b: Builder, r: _Reader, f, where: str) -> None:
    if not isinstance(f, dict) or f.get("type") not in ("box", "cylinder"):
        got = f.get("type") if isinstance(f, dict) else f
        r.fail(f"{where}.type", f"expected \"box\" or \"cylinder\", got {json.dumps(got)}")
    kind = f["type"]
    r.keys(f, where, _BOX if kind == "box" else _CYL, ("x", "y", "size" if kind == "box" else "radius"))
    x, y = r.number(f["x"], f"{where}.x", coordinate=True), r.number(f["y"], f"{where}.y", coordinate=True)
    h = r.number(f.get("height", 1.0), f"{where}.height", positive=True, size=True)
    color = r.color(f.get("color", (0.6, 0.6, 0.6)), f"{where}.color")
    movable = r.flag(f.get("movable", False), f"{where}.movable")
    name = r.name(f["name"], f"{where}.name") if "name" in f else None
    if kind == "box":
        sx, sy = r.vector(f["size"], f"{where}.size", 2, positive=True, size=True)
        yaw = r.number(f.get("yaw", 0.0), f"{where}.yaw")
        b.box(name or kind, x, y, sx, sy, h, color, yaw=yaw, movable=movable, name=name)
    else:
        rad = r.number(f["radius"], f"{where}.radius", positive=True, size=True)
        b.cyl(name or kind, x, y, rad, h, color, movable=movable, name=name)


def _extent(shapes) -> tuple[float, float, float, float]:
    from .geometry import shape_extent

    ext = np.array([shape_extent(s) for s in shapes])
    return (float(ext[:, 0].min()), float(ext[:, 1].min()), float(ext[:, 2].max()), float(ext[:, 3].max()))


# -- checks shared by JSON and images ------------------------------------------------------------------
def check_layout(layout: Layout, starts=None, source: str = "layout") -> Layout:
    """Validate the free space and the starts of ``layout`` (``starts`` None: sample
    :data:`NUM_SAMPLED_STARTS` distinct ones in the largest free region) and return it with its starts.

    The extent is bounded first (:func:`check_extent`), before the grid is allocated."""
    r = _Reader(source)
    check_extent(layout.bounds, source, "bounds")
    grid = layout_grid(layout, GRID_RESOLUTION)
    clear = grid.clearance() >= START_CLEARANCE
    # the border row and column of the grid count as outside: free space touching them is open
    labels, n = ndimage.label(clear, structure=np.ones((3, 3)))
    if n == 0:
        r.fail("", f"no free space: nowhere can a robot of radius {ROBOT_RADIUS} m stand clear of the walls")
    xmin, ymin, xmax, ymax = layout.bounds
    if starts is None:
        sizes = np.bincount(labels.ravel())[1:]
        biggest = int(np.argmax(sizes)) + 1
        starts = sample_starts(grid, labels == biggest, NUM_SAMPLED_STARTS)
    for i, (x, y, _) in enumerate(starts):
        if not (xmin < x < xmax and ymin < y < ymax):
            r.fail(f"starts[{i}]", f"({x:g}, {y:g}) lies outside the bounds {list(layout.bounds)}")
        rc = grid.world_to_cell([x, y])
        if grid.occupied[rc[0], rc[1]]:
            r.fail(f"starts[{i}]", f"({x:g}, {y:g}) lies inside an obstacle")
        if not clear[rc[0], rc[1]]:
            r.fail(f"starts[{i}]", f"({x:g}, {y:g}) is closer than {START_CLEARANCE:g} m to an obstacle (the robot "
                                   f"does not fit)")
    labs = [int(labels[tuple(grid.world_to_cell(s[:2]))]) for s in starts]
    for i, lab in enumerate(labs):
        if lab != labs[0]:
            r.fail(f"starts[{i}]", f"{list(starts[i][:2])} cannot be reached from starts[0] {list(starts[0][:2])} "
                                   f"(no passage wide enough for the robot)")
    region = labels == labs[0]
    if region[0, :].any() or region[-1, :].any() or region[:, 0].any() or region[:, -1].any():
        r.fail("walls", "the free space around the starts reaches the bounds: close the building with walls")
    return _with_starts(layout, starts)


def sample_starts(grid, region: np.ndarray, n: int, separation: float = 1.0, seed: int = 0):
    """``n`` poses (x, y, yaw) in ``region`` (cells), at least ``separation`` apart when possible,
    the first at the region's most open cell."""
    rng = np.random.default_rng(seed)
    cells = np.argwhere(region)
    clearance = grid.clearance()[region]
    xy = grid.cell_to_world(cells)
    chosen = [xy[int(np.argmax(clearance))]]
    for _ in range(50 * n):
        if len(chosen) == n:
            break
        p = xy[int(rng.integers(len(xy)))]
        if min(float(np.hypot(*(p - q))) for q in chosen) >= separation:
            chosen.append(p)
    return [(float(p[0]), float(p[1]), float(rng.uniform(-np.pi, np.pi))) for p in chosen]


# -- images ------------------------------------------------------------------------------------------
def png_size(path: Path) -> tuple[int, int]:
    """(width, height) from a PNG's header, without decoding it."""
    with open(path, "rb") as fh:
        head = fh.read(24)
    if len(head) < 24 or head[:8] != b"\x89PNG\r\n\x1a\n" or head[12:16] != b"IHDR":
        raise LayoutFileError(f"{path}: not a PNG image")
    return struct.unpack(">II", head[16:24])


def read_png_mask(path: Path) -> np.ndarray:
    """Boolean wall mask (True = dark pixel) of a PNG, its size bounded before decoding."""
    import cv2

    path = Path(path)
    regular_file_size(path, LayoutFileError, MAX_FILE_BYTES, "MAX_FILE_BYTES")
    w, h = png_size(path)
    if w * h > MAX_IMAGE_PIXELS or w == 0 or h == 0:
        raise LayoutFileError(f"{path}: {w} x {h} pixels, outside 1 .. {MAX_IMAGE_PIXELS} pixels for a plan")
    img = cv2.imread(str(path), cv2.IMREAD_GRAYSCALE)
    if img is None:
        raise LayoutFileError(f"{path}: unreadable PNG image")
    return img < 128


def _image_walls(b: Builder, mask: np.ndarray, scale: float, source: str):
    """Dark pixels as wall boxes (runs of pixels merged into rectangles), outer walls around the image."""
    h, w = mask.shape
    check_extent((0.0, 0.0, w * scale, h * scale), source, f"{w} x {h} pixels at metres_per_pixel {scale:g}")
    open_runs: dict[tuple[int, int], int] = {}  # (c0, c1) -> first row of a rectangle still growing
    rects = []
    for row in range(h + 1):
        runs = set()
        if row < h:
            m = np.concatenate([[False], mask[row], [False]]).astype(np.int8)
            d = np.diff(m)
            runs = set(zip(np.flatnonzero(d == 1).tolist(), np.flatnonzero(d == -1).tolist(), strict=True))
        for run in list(open_runs):
            if run not in runs:
                rects.append((open_runs.pop(run), row, *run))
        for run in runs:
            open_runs.setdefault(run, row)
        if len(rects) > MAX_SHAPES:
            raise LayoutFileError(f"{source}: more than {MAX_SHAPES} wall rectangles (simplify the plan)")
    W, H = w * scale, h * scale
    for r0, r1, c0, c1 in rects:  # rows r0..r1-1 (top = row 0), columns c0..c1-1
        x0, x1 = c0 * scale, c1 * scale
        y0, y1 = (h - r1) * scale, (h - r0) * scale
        b.box("wall", (x0 + x1) / 2, (y0 + y1) / 2, x1 - x0, y1 - y0, WALL_H, (0.8, 0.8, 0.75))
    return b.enclosure(W, H, [(0.8, 0.8, 0.75)] * 4)


def layout_from_image(path, metres_per_pixel: float = DEFAULT_METRES_PER_PIXEL, starts=None,
                      name: str | None = None, check_space: bool = True) -> Layout:
    """A layout whose walls are the dark pixels of a PNG plan (starts sampled when not given;
    ``check_space=False``: the free-space checks of :func:`check_layout` are skipped)."""
    if not (isinstance(metres_per_pixel, int | float) and metres_per_pixel > 0 and math.isfinite(metres_per_pixel)):
        raise LayoutFileError(f"{path}: metres_per_pixel must be a positive number, got {metres_per_pixel!r}")
    path = Path(path)
    b = Builder(0)
    bounds = _image_walls(b, read_png_mask(path), float(metres_per_pixel), str(path))
    layout = Layout(name or path.stem, tuple(float(v) for v in bounds), tuple(b.shapes), (), None, None)
    if not check_space:
        return layout if starts is None else _with_starts(layout, starts)
    return check_layout(layout, starts, str(path))


# -- files -------------------------------------------------------------------------------------------
def is_layout_file(env: str) -> bool:
    """Whether ``env`` names a layout file (``.json`` or ``.png``) rather than a built-in layout."""
    return str(env).lower().endswith((".json", ".png"))


def load_layout(path, metres_per_pixel: float | None = None, check_space: bool = True) -> Layout:
    """A layout from a JSON description or a PNG plan (see the module docstring).

    ``check_space=False`` reads and bounds every entry but skips the free-space and start checks
    (:func:`check_layout`), which rasterise the building: a quick check of the file."""
    path = Path(path)
    if path.suffix.lower() == ".png":
        return layout_from_image(path, metres_per_pixel or DEFAULT_METRES_PER_PIXEL, check_space=check_space)
    if path.suffix.lower() != ".json":
        raise LayoutFileError(f"{path}: expected a .json building or a .png plan")
    regular_file_size(path, LayoutFileError, MAX_FILE_BYTES, "MAX_FILE_BYTES")
    try:
        d = json.loads(path.read_text())
    except UnicodeDecodeError:
        raise LayoutFileError(f"{path}: not a text file") from None
    except json.JSONDecodeError as err:
        raise LayoutFileError(f"{path}: invalid JSON ({err.msg} at line {err.lineno}, column {err.colno})") from None
    return layout_from_dict(d, str(path), path.parent, check_space)


def layout_to_dict(layout: Layout) -> dict:
    """The JSON description of any layout (walls and furniture as boxes and cylinders)."""
    furniture = []
    for s in layout.shapes:
        if isinstance(s, Box):
            f = {"type": "box", "name": s.name, "x": s.x, "y": s.y, "size": [s.sx, s.sy], "height": s.height,
                 "yaw": s.yaw}
        elif isinstance(s, Cylinder):
            f = {"type": "cylinder", "name": s.name, "x": s.x, "y": s.y, "radius": s.radius, "height": s.height}
        else:  # pragma: no cover - layouts hold boxes and cylinders only
            raise TypeError(f"unsupported shape {s!r}")
        furniture.append({**f, "color": list(s.color), "movable": s.movable})
    d = {"format": FORMAT, "name": layout.name, "bounds": list(layout.bounds), "walls": [],
         "furniture": furniture, "starts": [list(p) for p in layout.starts]}
    if layout.texture_seed is not None:
        d["texture_seed"] = layout.texture_seed
    return d


def layout_to_json(layout: Layout, path=None) -> str:
    """``layout`` as JSON text (written to ``path`` when given); :func:`load_layout` reads it back."""
    d = layout_to_dict(layout)
    text = json.dumps(d, indent=1)
    if path is not None:
        Path(path).write_text(text)
    return text

"""Deterministic procedural textures and textured meshes for the pybullet scene.

Flat-coloured surfaces make every panorama of a room look alike to SSIM, so each shape
gets its own seeded pattern (wall panels and posters, rack shelving with cartons, striped
or checkered furniture, car bodies with windows and wheels) and the floor gets tiles with
varied shades. Patterns are pure functions of the layout name, the shape name and its
size, so two scenes built from the same layout render byte-identical images.

Textures are unrolled around the shape: the four side faces of a box (or the side of a
cylinder) take consecutive horizontal ranges of one image whose width is proportional
to the perimeter, so every face shows different content at the same pixels per metre.
Row 0 of a texture is the top of the shape.
"""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

import numpy as np

from .geometry import Box, Cylinder, Shape

PPM = 24.0  # texture pixels per metre on shapes
FLOOR_PPM = 16.0
MAX_WIDTH = 1536
# Detail scale. SSIM compares 11-pixel windows, so sharp fine patterns decorrelate after a
# few centimetres of motion while flat surfaces never do. Coarse patterns softened by a
# blur keep panoramas 0.25 m apart similar (SSIM ~0.75) and those 1 m apart dissimilar
# (~0.5); tests/envs/test_place_recognition.py holds the measured bounds.
STRIPE_M = (0.35, 0.8)  # stripe / checker periods on shapes, metres
FLOOR_TILE_M = 2.0  # floor tile size, metres
FLOOR_SHADES = (0.6, 1.3)  # per-tile brightness factors
GROUT = False  # thin grout lines between floor tiles
FLOOR_MARKS = False  # small painted marks on the floor
STAIN = 0.35  # amplitude of the large-scale floor shading
STAIN_M = 3.0  # its feature size, metres
BLUR_M = 0.35  # width of the tent blur applied to every texture, metres


# --------------------------------------------------------------------------- PNG output
def write_png(path: str | Path, rgb: np.ndarray) -> None:
    """Write an (h, w, 3) uint8 image as an 8-bit RGB PNG."""
    img = np.ascontiguousarray(rgb, np.uint8)
    h, w, _ = img.shape
    raw = np.concatenate([np.zeros((h, 1), np.uint8), img.reshape(h, w * 3)], 1).tobytes()

    def chunk(tag: bytes, data: bytes) -> bytes:
        return (struct.pack(">I", len(data)) + tag + data
                + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF))

    png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
           + chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))
    Path(path).write_bytes(png)


# --------------------------------------------------------------------------- helpers
def shape_rng(layout_name: str, shape_name: str) -> np.random.Generator:
    return np.random.default_rng(zlib.crc32(f"{layout_name}/{shape_name}".encode()))


def kind(shape_name: str) -> str:
    """'wall_03' -> 'wall', 'central_box' -> 'central_box'."""
    head, _, tail = shape_name.rpartition("_")
    return head if head and tail.isdigit() else shape_name


def _canvas(h: int, w: int, color) -> np.ndarray:
    return np.broadcast_to(np.asarray(color, np.float32), (h, w, 3)).copy()


def _shade(color, f) -> np.ndarray:
    return np.clip(np.asarray(color, np.float32) * f, 0.0, 1.0)


def _rand_color(rng, lo=0.1, hi=0.95) -> np.ndarray:
    return rng.uniform(lo, hi, 3).astype(np.float32)


def _rect(img, r0, r1, c0, c1, color) -> None:
    h, w, _ = img.shape
    r0, r1 = max(0, int(r0)), min(h, int(r1))
    c0, c1 = max(0, int(c0)), min(w, int(c1))
    if r1 > r0 and c1 > c0:
        img[r0:r1, c0:c1] = color


def _blotches(rng, h, w, cell) -> np.ndarray:
    """Smooth random field in [0, 1] with features about `cell` pixels across."""
    gh, gw = h // cell + 2, w // cell + 2
    g = rng.random((gh, gw)).astype(np.float32)
    ys = np.arange(h) / cell
    xs = np.arange(w) / cell
    y0, x0 = ys.astype(int), xs.astype(int)
    fy, fx = (ys - y0)[:, None], (xs - x0)[None, :]
    fy, fx = fy * fy * (3 - 2 * fy), fx * fx * (3 - 2 * fx)
    a = g[y0][:, x0] * (1 - fx) + g[y0][:, x0 + 1] * fx
    b = g[y0 + 1][:, x0] * (1 - fx) + g[y0 + 1][:, x0 + 1] * fx
    return a * (1 - fy) + b * fy


def _fill_pattern(rng, img, r0, r1, c0, c1, base) -> None:
    """One of: stripes, checkers, blotches, blocks, in region [r0:r1, c0:c1]."""
    h, w = r1 - r0, c1 - c0
    if h <= 0 or w <= 0:
        return
    other = _rand_color(rng)
    if float(np.mean(np.abs(other - base))) < 0.25:
        other = 1.0 - base
    choice = int(rng.integers(5))
    yy, xx = np.mgrid[0:h, 0:w]
    lo, hi = (max(2, int(v * PPM)) for v in STRIPE_M)
    p = int(rng.integers(lo, hi + 1))
    if choice == 0:  # vertical stripes
        mask = (xx // p) % 2 == 0
    elif choice == 1:  # horizontal stripes
        mask = (yy // p) % 2 == 0
    elif choice == 2:  # checkers
        mask = ((xx // p) + (yy // p)) % 2 == 0
    elif choice == 3:  # diagonal stripes
        mask = ((xx + yy * (1 if rng.random() < 0.5 else -1)) // p) % 2 == 0
    else:  # blotches
        mask = _blotches(rng, h, w, 2 * p) > 0.5
    region = img[r0:r1, c0:c1]
    region[mask] = other
    region[~mask] = base


def _box_blur(img: np.ndarray, r: int) -> np.ndarray:
    """Separable box blur of radius r (edge-clamped), applied twice (a tent filter)."""
    if r <= 0:
        return img
    for _ in range(2):
        for axis in (0, 1):
            pad = [(0, 0)] * img.ndim
            pad[axis] = (r + 1, r)
            c = np.cumsum(np.pad(img, pad, mode="edge"), axis=axis, dtype=np.float64)
            n = img.shape[axis]
            hi = np.take(c, np.arange(2 * r + 1, 2 * r + 1 + n), axis=axis)
            lo = np.take(c, np.arange(0, n), axis=axis)
            img = ((hi - lo) / (2 * r + 1)).astype(np.float32)
    return img


# --------------------------------------------------------------------------- patterns
def wall_texture(rng, w: int, h: int, base) -> np.ndarray:
    """Panels of varied shade, skirting, a dado rail and posters; (h, w, 3) float."""
    base = np.asarray(base, np.float32)
    img = _canvas(h, w, base)
    c = 0
    while c < w:  # vertical panels of varied width and shade
        pw = int(rng.uniform(0.25, 1.2) * PPM)
        img[:, c:c + pw] = _shade(base, rng.uniform(0.55, 1.15))
        if rng.random() < 0.3:  # thin dark seam
            img[:, c:c + 2] = _shade(base, 0.3)
        c += pw
    m = PPM
    skirting = _shade(_rand_color(rng, 0.05, 0.5), 1.0)
    _rect(img, h - 0.15 * m, h, 0, w, skirting)
    rail = h - int(rng.uniform(0.8, 1.0) * m)
    _rect(img, rail - 2, rail + 1, 0, w, _shade(base, 0.4))
    c = int(rng.uniform(0.0, 0.6) * m)
    while c < w:  # posters, frames, windows
        pw = int(rng.uniform(0.4, 1.1) * m)
        top = h - int(rng.uniform(1.1, 1.8) * m)
        bottom = h - int(rng.uniform(0.25, 0.7) * m)
        frame = _rand_color(rng, 0.0, 0.4) if rng.random() < 0.5 else _rand_color(rng, 0.7, 1.0)
        _rect(img, top - 2, bottom + 2, c - 2, c + pw + 2, frame)
        _fill_pattern(rng, img, max(top, 0), min(bottom, h), max(c, 0), min(c + pw, w),
                      _rand_color(rng))
        c += pw + int(rng.uniform(0.3, 1.4) * m)
    return img


def rack_texture(rng, w: int, h: int, base) -> np.ndarray:
    """Shelving: dark back, coloured beams, uprights, cartons of varied size and colour."""
    base = np.asarray(base, np.float32)
    img = _canvas(h, w, (0.08, 0.08, 0.1))
    m = PPM
    levels = np.arange(h, 0, -int(0.55 * m))  # beam rows from the bottom up
    for lvl in levels:
        top = lvl - int(0.55 * m)
        c = 0
        while c < w:  # cartons standing on this beam
            cw = int(rng.uniform(0.2, 0.7) * m)
            if rng.random() < 0.8:
                ch = int(rng.uniform(0.2, 0.45) * m)
                col = (_shade((0.65, 0.45, 0.25), rng.uniform(0.6, 1.3)) if rng.random() < 0.6
                       else _rand_color(rng))
                _rect(img, lvl - ch, lvl - 2, c + 1, c + cw - 1, col)
                if rng.random() < 0.5:  # label
                    _rect(img, lvl - ch + 3, lvl - ch + 6, c + 3, c + cw // 2, (0.95, 0.95, 0.9))
            c += cw
        _rect(img, lvl - 3, lvl, 0, w, _shade(base, 1.2))
        _rect(img, top, top + 1, 0, w, _shade(base, 0.6))
    c = 0
    while c < w:
        _rect(img, 0, h, c, c + 3, _shade(base, 0.7))
        c += int(rng.uniform(1.2, 2.0) * m)
    return img


def furniture_texture(rng, w: int, h: int, base) -> np.ndarray:
    """Base colour with a seeded pattern band, drawer or panel lines and an edge trim."""
    base = np.asarray(base, np.float32)
    img = _canvas(h, w, base)
    c = 0
    while c < w:  # segments of different patterns along the perimeter
        sw = int(rng.uniform(0.3, 1.0) * PPM)
        if rng.random() < 0.7:
            r0 = int(rng.uniform(0.0, 0.4) * h)
            r1 = int(rng.uniform(0.6, 1.0) * h)
            _fill_pattern(rng, img, r0, r1, c, min(c + sw, w), _shade(base, rng.uniform(0.6, 1.2)))
        else:
            img[:, c:c + sw] = _shade(base, rng.uniform(0.5, 1.2))
        _rect(img, 0, h, c, c + 2, _shade(base, 0.35))
        c += sw
    _rect(img, 0, 3, 0, w, _shade(base, 0.4))
    _rect(img, h - 3, h, 0, w, _shade(base, 0.3))
    return img


def car_texture(rng, w: int, h: int, base, sides) -> np.ndarray:
    """Body colour, dark windows band, wheels near the bottom, door seams, lights."""
    base = np.asarray(base, np.float32)
    img = _canvas(h, w, base)
    m = PPM
    c = 0
    for i, sw in enumerate(sides):
        sw = int(sw)
        long_side = i % 2 == 1
        _rect(img, int(0.08 * h), int(0.4 * h), c + 3, c + sw - 3, (0.12, 0.14, 0.2))
        _rect(img, int(0.42 * h), int(0.45 * h), c, c + sw, _shade(base, 0.6))
        if long_side:
            for fx in (0.2, 0.8):
                cx = c + fx * sw
                r = 0.33 * m
                yy, xx = np.mgrid[0:h, 0:w]
                disc = (xx - cx) ** 2 + (yy - (h - 0.3 * m)) ** 2 < r * r
                img[disc] = (0.05, 0.05, 0.05)
                hub = (xx - cx) ** 2 + (yy - (h - 0.3 * m)) ** 2 < (0.4 * r) ** 2
                img[hub] = (0.7, 0.7, 0.72)
            _rect(img, int(0.45 * h), int(0.75 * h), c + sw // 2, c + sw // 2 + 2,
                  _shade(base, 0.4))
        else:
            lc = (1.0, 0.95, 0.7) if i == 0 else (0.85, 0.1, 0.1)
            _rect(img, int(0.5 * h), int(0.6 * h), c + 3, c + sw // 4, lc)
            _rect(img, int(0.5 * h), int(0.6 * h), c + sw - sw // 4, c + sw - 3, lc)
            _rect(img, int(0.65 * h), int(0.72 * h), c + sw // 3, c + 2 * sw // 3,
                  (0.95, 0.95, 0.95))
        c += sw
    return img


def floor_texture(rng, w: int, h: int, tile_px: int, base) -> np.ndarray:
    """Tiles of varied shade with grout lines and a large-scale stain pattern."""
    base = np.asarray(base, np.float32)
    ny, nx = h // tile_px + 1, w // tile_px + 1
    shades = rng.uniform(*FLOOR_SHADES, (ny, nx)).astype(np.float32)
    tint = rng.uniform(-0.08, 0.08, (ny, nx, 3)).astype(np.float32)
    yy, xx = np.mgrid[0:h, 0:w]
    ty, tx = yy // tile_px, xx // tile_px
    img = np.clip(base * shades[ty, tx][..., None] + tint[ty, tx], 0, 1)
    stain = _blotches(rng, h, w, max(2, int(STAIN_M * FLOOR_PPM)))
    img *= (1.0 - STAIN / 2 + STAIN * stain)[..., None]
    if GROUT:
        grout = ((yy % tile_px) < 1) | ((xx % tile_px) < 1)
        img[grout] = _shade(base, 0.5)
    # a few painted marks (arrows, spots) for local structure
    for _ in range(max(1, (w * h) // (tile_px * tile_px * 6)) if FLOOR_MARKS else 0):
        r, c = int(rng.integers(h)), int(rng.integers(w))
        s = int(rng.integers(3, max(4, tile_px // 2)))
        _rect(img, r, r + s, c, c + s, _rand_color(rng, 0.05, 1.0))
    return np.clip(img, 0, 1)


# --------------------------------------------------------------------------- per shape
def _perimeter_sides(s: Shape) -> list[float]:
    if isinstance(s, Box):
        return [s.sx, s.sy, s.sx, s.sy]
    return [2 * np.pi * s.radius]


def shape_texture(layout_name: str, s: Shape) -> np.ndarray:
    """(h, w, 3) uint8 texture for one shape, unrolled around its sides."""
    rng = shape_rng(layout_name, s.name)
    sides = _perimeter_sides(s)
    scale = min(1.0, MAX_WIDTH / (sum(sides) * PPM))
    sides_px = [max(4, int(round(v * PPM * scale))) for v in sides]
    w = sum(sides_px)
    h = max(8, int(round(s.height * PPM)))
    k = kind(s.name)
    if k == "wall":
        img = wall_texture(rng, w, h, s.color)
    elif k in ("rack", "shelf", "wardrobe", "counter", "booth"):
        img = rack_texture(rng, w, h, s.color) if k in ("rack", "shelf") else \
            wall_texture(rng, w, h, s.color)
    elif k == "car":
        img = car_texture(rng, w, h, s.color, sides_px)
    else:
        img = furniture_texture(rng, w, h, s.color)
    img = _box_blur(img, int(BLUR_M * PPM / 2))
    return (np.clip(img, 0, 1) * 255 + 0.5).astype(np.uint8)


def layout_floor_texture(layout_name: str, size_xy, base) -> np.ndarray:
    rng = shape_rng(layout_name, "floor")
    w = max(16, int(round(size_xy[0] * FLOOR_PPM)))
    h = max(16, int(round(size_xy[1] * FLOOR_PPM)))
    img = floor_texture(rng, w, h, max(4, int(FLOOR_TILE_M * FLOOR_PPM)), base)
    img = _box_blur(img, int(BLUR_M * FLOOR_PPM / 2))
    return (img * 255 + 0.5).astype(np.uint8)


# --------------------------------------------------------------------------- meshes
def box_mesh(sx: float, sy: float, sz: float):
    """Vertices, indices, uvs, normals of a box centred at the origin.

    Side faces (S, E, N, W, counter-clockwise seen from above) take consecutive u ranges
    proportional to their widths; v runs bottom (0) to top (1). Top and bottom faces map
    to a thin strip at the start of the texture.
    """
    hx, hy, hz = sx / 2, sy / 2, sz / 2
    sides = [((0, -hy), (1, 0), sx), ((hx, 0), (0, 1), sy), ((0, hy), (-1, 0), sx),
             ((-hx, 0), (0, -1), sy)]
    per = 2 * (sx + sy)
    verts, idx, uvs, nrm = [], [], [], []
    u0 = 0.0
    for (cx, cy), (ux, uy), width in sides:
        u1 = u0 + width / per
        n = (uy, -ux, 0.0)  # outward normal: u rotated clockwise
        base = len(verts)
        for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
            verts.append([cx + a * ux * width / 2, cy + a * uy * width / 2, b * hz])
            uvs.append([u0 if a < 0 else u1, 0.0 if b < 0 else 1.0])
            nrm.append(list(n))
        idx += [base, base + 1, base + 2, base, base + 2, base + 3]
        u0 = u1
    for sz_sign in (1, -1):
        base = len(verts)
        corners = ((-1, -1), (1, -1), (1, 1), (-1, 1))
        if sz_sign < 0:
            corners = corners[::-1]
        for a, b in corners:
            verts.append([a * hx, b * hy, sz_sign * hz])
            uvs.append([0.002 * (a + 1), 0.99 + 0.005 * (b + 1)])
            nrm.append([0.0, 0.0, float(sz_sign)])
        idx += [base, base + 1, base + 2, base, base + 2, base + 3]
    return verts, idx, uvs, nrm


def cylinder_mesh(radius: float, height: float, segments: int = 12):
    """Side of a cylinder (u around, v up) and two caps, centred at the origin."""
    hz = height / 2
    verts, idx, uvs, nrm = [], [], [], []
    for i in range(segments + 1):
        a = 2 * np.pi * i / segments
        c, s = float(np.cos(a)), float(np.sin(a))
        for z, v in ((-hz, 0.0), (hz, 1.0)):
            verts.append([radius * c, radius * s, z])
            uvs.append([i / segments, v])
            nrm.append([c, s, 0.0])
    for i in range(segments):
        a, b = 2 * i, 2 * i + 2
        idx += [a, b, b + 1, a, b + 1, a + 1]
    for z, sign in ((hz, 1.0), (-hz, -1.0)):
        centre = len(verts)
        verts.append([0.0, 0.0, z])
        uvs.append([0.0, 0.995])
        nrm.append([0.0, 0.0, sign])
        for i in range(segments):
            a = 2 * np.pi * i / segments
            verts.append([radius * float(np.cos(a)), radius * float(np.sin(a)), z])
            uvs.append([0.0, 0.995])
            nrm.append([0.0, 0.0, sign])
        for i in range(segments):
            j, k = centre + 1 + i, centre + 1 + (i + 1) % segments
            idx += [centre, j, k] if sign > 0 else [centre, k, j]
    return verts, idx, uvs, nrm


def quad_mesh(sx: float, sy: float):
    """An upward-facing rectangle at z = 0 with uvs over the whole texture."""
    hx, hy = sx / 2, sy / 2
    verts = [[-hx, -hy, 0.0], [hx, -hy, 0.0], [hx, hy, 0.0], [-hx, hy, 0.0]]
    uvs = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
    nrm = [[0.0, 0.0, 1.0]] * 4
    return verts, [0, 1, 2, 0, 2, 3], uvs, nrm


__all__ = ["Box", "Cylinder", "box_mesh", "cylinder_mesh", "floor_texture",
           "layout_floor_texture", "quad_mesh", "shape_texture", "write_png"]

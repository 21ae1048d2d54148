"""Primitive shapes and exact 2D signed distances (no physics client needed)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

RGB = tuple[float, float, float]


@dataclass(frozen=True)
class Box:
    """Upright box obstacle.

    Attributes
    ----------
    name : str
        Unique name within a layout.
    x, y : float
        Centre, metres, world frame.
    sx, sy : float
        Full footprint sizes along the box's own axes, metres.
    height : float
        Height in metres, default 1.
    yaw : float
        Rotation about the vertical axis, radians, default 0.
    color : tuple of float
        RGB in [0, 1].
    movable : bool
        Whether scenarios may move it.
    """

    name: str
    x: float
    y: float
    sx: float
    sy: float
    height: float = 1.0
    yaw: float = 0.0
    color: RGB = (0.6, 0.6, 0.6)
    movable: bool = False


@dataclass(frozen=True)
class Cylinder:
    """Upright cylinder obstacle.

    Attributes
    ----------
    name : str
        Unique name within a layout.
    x, y : float
        Centre, metres, world frame.
    radius : float
        Radius in metres.
    height : float
        Height in metres, default 1.
    color : tuple of float
        RGB in [0, 1].
    movable : bool
        Whether scenarios may move it.
    """

    name: str
    x: float
    y: float
    radius: float
    height: float = 1.0
    color: RGB = (0.6, 0.6, 0.6)
    movable: bool = False


Shape = Box | Cylinder


class ShapeSet:
    """Shapes packed into arrays so distances can be computed for many points at once."""

    def __init__(self, shapes: tuple[Shape, ...] | list[Shape]):
        boxes = [s for s in shapes if isinstance(s, Box)]
        cyls = [s for s in shapes if isinstance(s, Cylinder)]
        self.box_c = np.array([[b.x, b.y] for b in boxes], float).reshape(-1, 2)
        self.box_h = np.array([[b.sx / 2, b.sy / 2] for b in boxes], float).reshape(-1, 2)
        yaw = np.array([b.yaw for b in boxes], float)
        self.box_cos, self.box_sin = np.cos(yaw), np.sin(yaw)
        self.cyl_c = np.array([[c.x, c.y] for c in cyls], float).reshape(-1, 2)
        self.cyl_r = np.array([c.radius for c in cyls], float)

    def distance(self, points: np.ndarray) -> np.ndarray:
        """Signed distance (m) from each point (K, 2) to the nearest shape; negative inside."""
        pts = np.asarray(points, float).reshape(-1, 2)
        best = np.full(len(pts), np.inf)
        if len(self.box_c):
            best = np.minimum(best, box_distance(
                pts, self.box_c, self.box_h, self.box_cos, self.box_sin).min(axis=1))
        if len(self.cyl_c):
            d = np.linalg.norm(pts[:, None, :] - self.cyl_c[None], axis=2) - self.cyl_r[None]
            best = np.minimum(best, d.min(axis=1))
        return best


def box_distance(pts, centres, halves, cos, sin) -> np.ndarray:
    """Signed distance of points (K, 2) to boxes (N,), shape (K, N)."""
    d = pts[:, None, :] - centres[None]
    lx = d[..., 0] * cos[None] + d[..., 1] * sin[None]
    ly = -d[..., 0] * sin[None] + d[..., 1] * cos[None]
    qx = np.abs(lx) - halves[None, :, 0]
    qy = np.abs(ly) - halves[None, :, 1]
    outside = np.hypot(np.maximum(qx, 0.0), np.maximum(qy, 0.0))
    inside = np.minimum(np.maximum(qx, qy), 0.0)
    return outside + inside


def shape_distance(shape: Shape, points: np.ndarray) -> np.ndarray:
    """Signed distance of points (K, 2) to one shape."""
    return ShapeSet([shape]).distance(points)


def shape_extent(shape: Shape) -> tuple[float, float, float, float]:
    """Axis-aligned bounding box (xmin, ymin, xmax, ymax) of a shape footprint."""
    if isinstance(shape, Cylinder):
        r = shape.radius
        return shape.x - r, shape.y - r, shape.x + r, shape.y + r
    c, s = abs(np.cos(shape.yaw)), abs(np.sin(shape.yaw))
    ex = c * shape.sx / 2 + s * shape.sy / 2
    ey = s * shape.sx / 2 + c * shape.sy / 2
    return shape.x - ex, shape.y - ey, shape.x + ex, shape.y + ey


def shape_area(shape: Shape) -> float:
    """Footprint area in m2."""
    if isinstance(shape, Cylinder):
        return float(np.pi * shape.radius**2)
    return shape.sx * shape.sy

"""pybullet scene built from a layout (DIRECT mode, one client per scene)."""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

import numpy as np
import pybullet as p

from .geometry import Box, Cylinder
from .layouts import Layout
from .textures import (
    box_mesh,
    cylinder_mesh,
    layout_floor_texture,
    quad_mesh,
    shape_texture,
    write_png,
)

FLOOR_RGBA = (0.55, 0.55, 0.5, 1.0)


EYE_OFFSET = (3.7e-7, -2.9e-7, 1.3e-7)  # metres; see PyBulletScene.view
# metres: no mesh vertex may lie this close to the camera's own plane (see PyBulletScene.view)
VERTEX_CLEARANCE = 1e-3


def _quat(yaw: float):
    return (0.0, 0.0, float(np.sin(yaw / 2)), float(np.cos(yaw / 2)))


WHITE = (1.0, 1.0, 1.0, 1.0)


class PyBulletScene:
    """Static shapes as zero-mass bodies, a cylinder robot, rays and a pinhole camera.

    With `textured` (the default) every shape and the floor are textured meshes whose
    seeded patterns (see `textures`) give camera images structure; collision shapes stay
    primitive boxes and cylinders. Texture PNGs are written to a temporary directory that
    is removed once pybullet has loaded them.
    """

    def __init__(self, layout: Layout, robot_radius: float = 0.22, robot_height: float = 0.2,
                 textured: bool = True):
        self.client = p.connect(p.DIRECT)
        self.bodies: dict[str, int] = {}
        self.heights: dict[str, float] = {}
        self.textured = textured
        self.layout_name = layout.name
        cid = self.client
        tmp = Path(tempfile.mkdtemp(prefix="cogmap_tex_")) if textured else None
        try:
            xmin, ymin, xmax, ymax = layout.bounds
            size = ((xmax - xmin) + 2.0, (ymax - ymin) + 2.0)
            centre = [(xmin + xmax) / 2, (ymin + ymax) / 2]
            if textured:
                v, i, uv, n = quad_mesh(*size)
                vis = p.createVisualShape(p.GEOM_MESH, vertices=v, indices=i, uvs=uv, normals=n,
                                          rgbaColor=WHITE, physicsClientId=cid)
                self.floor = p.createMultiBody(0, -1, vis, [*centre, 0.0], physicsClientId=cid)
                tex = layout_floor_texture(layout.texture_name, size, FLOOR_RGBA[:3])
                self._texture(self.floor, tex, tmp / "floor.png")
            else:
                half = [size[0] / 2, size[1] / 2, 0.01]
                vis = p.createVisualShape(p.GEOM_BOX, halfExtents=half, rgbaColor=FLOOR_RGBA,
                                          physicsClientId=cid)
                self.floor = p.createMultiBody(0, -1, vis, [*centre, -0.01],
                                               physicsClientId=cid)
            for k, s in enumerate(layout.shapes):
                self.bodies[s.name] = self._add(s)
                self.heights[s.name] = s.height
                if textured:
                    self._texture(self.bodies[s.name], shape_texture(layout.texture_name, s),
                                  tmp / f"shape_{k:04d}.png")
        finally:
            if tmp is not None:
                shutil.rmtree(tmp, ignore_errors=True)
        col = p.createCollisionShape(p.GEOM_CYLINDER, radius=robot_radius, height=robot_height,
                                     physicsClientId=cid)
        # a tiny invisible visual keeps the robot out of its own camera images
        vis = p.createVisualShape(p.GEOM_SPHERE, radius=1e-3, rgbaColor=(0, 0, 0, 0),
                                  physicsClientId=cid)
        self.robot_height = robot_height
        self.robot = p.createMultiBody(0, col, vis, [0, 0, robot_height / 2],
                                       physicsClientId=cid)
        self.names = {v: k for k, v in self.bodies.items()}
        self._proj = {}
        # horizontal outline vertices of every visual mesh (body frame) and where they are now,
        # for the camera guard of view()
        self._outline = {name: _outline(s) for name, s in zip(self.bodies, layout.shapes, strict=True)}
        self._poses = {s.name: (s.x, s.y, getattr(s, "yaw", 0.0)) for s in layout.shapes}
        hx, hy = size[0] / 2, size[1] / 2
        self._floor_xy = np.array([[centre[0] + a * hx, centre[1] + b * hy] for a in (-1, 1) for b in (-1, 1)])
        self._vertex_xy = None

    def _texture(self, body: int, rgb: np.ndarray, path: Path) -> None:
        write_png(path, rgb)
        tex = p.loadTexture(str(path), physicsClientId=self.client)
        p.changeVisualShape(body, -1, textureUniqueId=tex, physicsClientId=self.client)

    def _mesh(self, mesh) -> int:
        v, i, uv, n = mesh
        return p.createVisualShape(p.GEOM_MESH, vertices=v, indices=i, uvs=uv, normals=n,
                                   rgbaColor=WHITE, physicsClientId=self.client)

    def _add(self, s) -> int:
        cid = self.client
        rgba = (*s.color, 1.0)
        if isinstance(s, Box):
            he = [s.sx / 2, s.sy / 2, s.height / 2]
            col = p.createCollisionShape(p.GEOM_BOX, halfExtents=he, physicsClientId=cid)
            if self.textured:
                vis = self._mesh(box_mesh(s.sx, s.sy, s.height))
            else:
                vis = p.createVisualShape(p.GEOM_BOX, halfExtents=he, rgbaColor=rgba,
                                          physicsClientId=cid)
            yaw = s.yaw
        elif isinstance(s, Cylinder):
            col = p.createCollisionShape(p.GEOM_CYLINDER, radius=s.radius, height=s.height,
                                         physicsClientId=cid)
            if self.textured:
                vis = self._mesh(cylinder_mesh(s.radius, s.height))
            else:
                vis = p.createVisualShape(p.GEOM_CYLINDER, radius=s.radius, length=s.height,
                                          rgbaColor=rgba, physicsClientId=cid)
            yaw = 0.0
        else:  # pragma: no cover - layouts only hold boxes and cylinders
            raise TypeError(f"unsupported shape {s!r}")
        return p.createMultiBody(0, col, vis, [s.x, s.y, s.height / 2], _quat(yaw),
                                 physicsClientId=cid)

    def set_robot(self, pose) -> None:
        p.resetBasePositionAndOrientation(self.robot, [pose[0], pose[1], self.robot_height / 2],
                                          _quat(pose[2]), physicsClientId=self.client)

    def move_body(self, name: str, x: float, y: float, yaw: float = 0.0) -> None:
        p.resetBasePositionAndOrientation(self.bodies[name], [x, y, self.heights[name] / 2],
                                          _quat(yaw), physicsClientId=self.client)
        self._poses[name] = (x, y, yaw)
        self._vertex_xy = None

    def vertex_xy(self) -> np.ndarray:
        """``(V, 2)`` horizontal positions (metres) of every visual mesh vertex now: the corners
        of boxes and of the floor, the rim vertices of cylinders."""
        if self._vertex_xy is None:
            parts = [self._floor_xy]
            for name, local in self._outline.items():
                x, y, yaw = self._poses[name]
                c, s_ = np.cos(yaw), np.sin(yaw)
                parts.append(local @ np.array([[c, s_], [-s_, c]]) + np.array([x, y]))
            self._vertex_xy = np.vstack(parts)
        return self._vertex_xy

    def cast(self, origin_xy, headings, z: float, r_min: float, r_max: float):
        """Horizontal rays from `r_min` to `r_max` around origin at height z.

        Starting outside the robot disc excludes the robot body. Returns ranges measured from
        the origin (r_max where nothing is hit) and the hit body ids (-1 for no hit).
        """
        c, s = np.cos(headings), np.sin(headings)
        ox, oy = float(origin_xy[0]), float(origin_xy[1])
        frm = np.stack([ox + r_min * c, oy + r_min * s, np.full_like(c, z)], 1)
        to = np.stack([ox + r_max * c, oy + r_max * s, np.full_like(c, z)], 1)
        out = p.rayTestBatch(frm, to, physicsClientId=self.client)
        ids = np.array([o[0] for o in out])
        frac = np.array([o[2] for o in out])
        hit = (ids >= 0) & (ids != self.robot)
        ranges = np.where(hit, r_min + frac * (r_max - r_min), r_max)
        return ranges, np.where(hit, ids, -1)

    def view(self, eye_xy, z: float, heading: float, width: int, height: int,
             fov_deg: float) -> np.ndarray:
        """One RGB image (height, width, 3) looking horizontally along `heading`."""
        key = (width, height, fov_deg)
        if key not in self._proj:
            self._proj[key] = p.computeProjectionMatrixFOV(fov_deg, width / height, 0.05, 30.0)
        # pybullet's TinyRenderer does not clip triangles at the camera: a mesh vertex lying in (or
        # within a hair of) the camera's own plane, the plane through the eye across the view,
        # projects to coordinates beyond any integer and the rasteriser never returns. Walls sit
        # on round coordinates, and so do moves on a lattice, so it happens in ordinary layouts,
        # from vertices metres to the side. The eye steps back along the view (2 mm at a time,
        # far below a pixel) until every vertex is VERTEX_CLEARANCE away from that plane; the
        # sub-micron offset keeps it off exact planes of the lattice as well.
        eye = np.array([float(eye_xy[0]) + EYE_OFFSET[0], float(eye_xy[1]) + EYE_OFFSET[1], z + EYE_OFFSET[2]])
        view_dir = np.array([np.cos(heading), np.sin(heading)])
        xy = self.vertex_xy()
        for _ in range(16):
            if not (np.abs((xy - eye[:2]) @ view_dir) < VERTEX_CLEARANCE).any():
                break
            eye[:2] -= 2 * VERTEX_CLEARANCE * view_dir
        eye = eye.tolist()
        tgt = [eye[0] + np.cos(heading), eye[1] + np.sin(heading), eye[2]]
        vm = p.computeViewMatrix(eye, tgt, [0, 0, 1])
        _, _, rgba, _, _ = p.getCameraImage(width, height, vm, self._proj[key],
                                            renderer=p.ER_TINY_RENDERER, shadow=0,
                                            physicsClientId=self.client)
        return np.asarray(rgba, np.uint8).reshape(height, width, 4)[..., :3]

    def closest_distance(self, name: str, max_dist: float = 1.0) -> float:
        """pybullet's closest distance between the robot and one body (for cross-checks)."""
        pts = p.getClosestPoints(self.robot, self.bodies[name], max_dist,
                                 physicsClientId=self.client)
        return min((q[8] for q in pts), default=np.inf)

    def close(self) -> None:
        if self.client is not None and p.isConnected(self.client):
            p.disconnect(self.client)
        self.client = None


def _outline(shape, segments: int = 12) -> np.ndarray:
    """Horizontal vertices (body frame, metres) of a shape's visual mesh: a box's four corners,
    a cylinder's rim (the ``segments`` of :func:`textures.cylinder_mesh`, which also bound
    pybullet's own cylinder tessellation closely enough for the camera guard)."""
    if isinstance(shape, Box):
        hx, hy = shape.sx / 2, shape.sy / 2
        return np.array([[-hx, -hy], [hx, -hy], [hx, hy], [-hx, hy]])
    a = 2 * np.pi * np.arange(segments) / segments
    return shape.radius * np.stack([np.cos(a), np.sin(a)], axis=1)

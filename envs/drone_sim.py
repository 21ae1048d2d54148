"""`DroneSim`: a 3D obstacle field in pybullet (DIRECT), a 0.25 m sphere drone and a 3D LiDAR.

Flight (DRONE.md 2.8): the drone is moved with ``resetBasePositionAndOrientation`` along a straight
segment at a commanded speed (2 m/s, 1.5 m/s when dense or near the goal), dt = 0.05 s. Every
sub-step checks contact with ``getClosestPoints(drone, body, 0.0)`` against the shapes whose bounds
are near (ground included). A collision is counted and stops the segment at the last free position;
the episode goes on (as the original) unless ``end_on_collision`` is set, then ``crashed`` is True.

LiDAR: 16 channels over +-10 deg x 25 azimuths = 400 rays, 20 m range, cast with ``rayTestBatch``
from the drone centre (rays start just outside the sphere). Each scan turns the azimuth pattern by a
golden-ratio fraction of the azimuth spacing, as a spinning LiDAR's start angle drifts, so
successive scans fill the gaps between azimuths. Hits on the ground plane are reported apart: the
perception treats the ground as a floor constraint, not as obstacle voxels.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pybullet as p

from .drone_field import Field, FieldConfig, make_field, sample_target

GOLDEN = (np.sqrt(5.0) - 1.0) / 2.0


@dataclass(frozen=True)
class DroneConfig:
    radius: float = 0.25
    dt: float = 0.05
    speed: float = 2.0
    slow_speed: float = 1.5
    lidar_channels: int = 16
    lidar_azimuths: int = 25
    lidar_vfov_deg: float = 10.0  # +- this
    lidar_range: float = 20.0
    end_on_collision: bool = False
    field: FieldConfig = field(default_factory=FieldConfig)

    @property
    def n_rays(self) -> int:
        return self.lidar_channels * self.lidar_azimuths


@dataclass
class Scan:
    """One LiDAR sweep: ray directions (N, 3), ranges (N,), world hit points of obstacle hits
    (K, 3) and of ground hits (G, 3)."""

    directions: np.ndarray
    ranges: np.ndarray
    points: np.ndarray
    ground: np.ndarray

    @property
    def min_range(self) -> float:
        """Nearest obstacle return (m), inf when no obstacle was hit."""
        if len(self.points) == 0:
            return float("inf")
        hit = self.ranges[np.isfinite(self.ranges)]
        return float(hit.min()) if len(hit) else float("inf")


@dataclass
class Flight:
    """Outcome of one commanded segment."""

    start: np.ndarray
    end: np.ndarray
    reached: bool
    collided: bool
    replanned: bool
    duration: float  # simulated seconds
    path: np.ndarray  # (K, 3) positions at every sub-step
    min_clearance: float  # nearest LiDAR obstacle return seen during the segment
    contact: np.ndarray | None = None  # (3,) the touched point of the obstacle (or ground) on a collision


def lidar_directions(channels: int, azimuths: int, vfov_deg: float, offset: float = 0.0) -> np.ndarray:
    """Unit ray directions (channels * azimuths, 3), z up; azimuth pattern turned by ``offset`` rad."""
    el = np.deg2rad(np.linspace(-vfov_deg, vfov_deg, channels))
    az = offset + 2 * np.pi * np.arange(azimuths) / azimuths
    E, A = np.meshgrid(el, az, indexing="ij")
    return np.stack([np.cos(E) * np.cos(A), np.cos(E) * np.sin(A), np.sin(E)], -1).reshape(-1, 3)


class DroneSim:
    """The field in pybullet plus the drone; see the module docstring."""

    def __init__(self, field_seed: int = 0, config: DroneConfig | None = None, field_: Field | None = None):
        self.config = config or DroneConfig()
        self.field = field_ or make_field(field_seed, self.config.field)
        self.client = p.connect(p.DIRECT)
        self._build()
        self.lo, self.hi = self.field.bounds3()
        self.reset()

    # ------------------------------------------------------------------ scene
    def _build(self) -> None:
        cid = self.client
        H = self.field.half_size + 10.0
        plane = p.createCollisionShape(p.GEOM_BOX, halfExtents=[H, H, 0.5], physicsClientId=cid)
        self.ground = p.createMultiBody(0, plane, -1, [0, 0, -0.5], physicsClientId=cid)
        self.bodies: list[int] = []
        for b in self.field.blocks:
            col = p.createCollisionShape(p.GEOM_BOX, halfExtents=[b.sx / 2, b.sy / 2, b.sz / 2], physicsClientId=cid)
            self.bodies.append(p.createMultiBody(0, col, -1, [b.x, b.y, b.z], physicsClientId=cid))
        for t in self.field.trunks:
            col = p.createCollisionShape(p.GEOM_CYLINDER, radius=t.radius, height=t.height, physicsClientId=cid)
            self.bodies.append(p.createMultiBody(0, col, -1, [t.x, t.y, t.height / 2], physicsClientId=cid))
        for c in self.field.crowns:
            col = p.createCollisionShape(p.GEOM_SPHERE, radius=c.radius, physicsClientId=cid)
            self.bodies.append(p.createMultiBody(0, col, -1, [c.x, c.y, c.z], physicsClientId=cid))
        col = p.createCollisionShape(p.GEOM_SPHERE, radius=self.config.radius, physicsClientId=cid)
        self.drone = p.createMultiBody(0, col, -1, list(self.field.start), physicsClientId=cid)
        self._max_batch = int(getattr(p, "MAX_RAY_INTERSECTION_BATCH_SIZE", 16384))

    def close(self) -> None:
        if self.client is not None and p.isConnected(self.client):
            p.disconnect(self.client)
        self.client = None

    # ------------------------------------------------------------------ state
    def reset(self, position=None) -> np.ndarray:
        """Put the drone at ``position`` (default: the field's start after take-off); clear the
        clock, collision count and path."""
        self.position = np.asarray(self.field.start if position is None else position, float).copy()
        self.time = 0.0
        self.collisions = 0
        self.crashed = False
        self.scans = 0
        self.last_contact = None
        self.path = [self.position.copy()]
        self._place(self.position)
        return self.position.copy()

    def _place(self, pos) -> None:
        p.resetBasePositionAndOrientation(self.drone, [float(v) for v in pos], [0, 0, 0, 1],
                                          physicsClientId=self.client)

    def sample_target(self, rng: np.random.Generator, **kw) -> np.ndarray:
        """A target 15-100 m away at 2-20 m altitude, outside geometry and validated by ray casts."""
        return sample_target(self.field, rng, ray_check=self.target_free, **kw)

    def target_free(self, point, reach: float = 1.5) -> bool:
        """Ray-cast validation of a target: the six axis rays of length ``reach`` from the point hit
        nothing, and a ray from the point straight down reaches the ground first when nothing is
        overhead (a point inside a shape would see the shape's far faces from inside)."""
        q = np.asarray(point, float)
        dirs = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)
        out = p.rayTestBatch((q + 0 * dirs).tolist(), (q + reach * dirs).tolist(), physicsClientId=self.client)
        if any(o[0] >= 0 for o in out):
            return False
        inward = p.rayTestBatch((q + reach * dirs).tolist(), q[None].repeat(6, 0).tolist(),
                                physicsClientId=self.client)
        return not any(o[0] >= 0 for o in inward)

    # ------------------------------------------------------------------ contact
    def contact(self, pos) -> bool:
        """True when the drone sphere at ``pos`` touches a shape or the ground (pybullet closest
        points); the touched point is then kept in ``last_contact`` (the impact point a simulator's
        collision report gives)."""
        r = self.config.radius
        pos = np.asarray(pos, float)
        if pos[2] <= r:
            self.last_contact = np.array([pos[0], pos[1], 0.0])
            return True
        near = np.flatnonzero(((self.lo - r - 0.05) <= pos).all(1) & ((self.hi + r + 0.05) >= pos).all(1))
        if len(near) == 0:
            return False
        self._place(pos)
        for k in near:
            pts = p.getClosestPoints(self.drone, self.bodies[k], 0.0, physicsClientId=self.client)
            if pts:
                self.last_contact = np.asarray(pts[0][6], float)  # position on the obstacle
                return True
        return False

    # ------------------------------------------------------------------ sensing
    def scan(self, position=None) -> Scan:
        """One LiDAR sweep from ``position`` (default: the drone's)."""
        c = self.config
        pos = self.position if position is None else np.asarray(position, float)
        spacing = 2 * np.pi / c.lidar_azimuths
        dirs = lidar_directions(c.lidar_channels, c.lidar_azimuths, c.lidar_vfov_deg,
                                offset=(self.scans * GOLDEN % 1.0) * spacing)
        self.scans += 1
        r0 = c.radius + 0.02
        frm = pos + r0 * dirs
        to = pos + c.lidar_range * dirs
        out = []
        for i in range(0, len(dirs), self._max_batch):
            out += p.rayTestBatch(frm[i:i + self._max_batch].tolist(), to[i:i + self._max_batch].tolist(),
                                  physicsClientId=self.client)
        ids = np.array([o[0] for o in out])
        frac = np.array([o[2] for o in out])
        dist = r0 + frac * (c.lidar_range - r0)
        hits = pos + dist[:, None] * dirs
        obstacle = (ids >= 0) & (ids != self.ground) & (ids != self.drone)
        ground = ids == self.ground
        ranges = np.where(obstacle, dist, np.inf)
        return Scan(dirs, ranges, hits[obstacle], hits[ground])

    # ------------------------------------------------------------------ flight
    def fly_to(self, waypoint, speed: float | None = None, replan_distance: float | None = None,
               scan_every: int = 5, on_scan=None) -> Flight:
        """Fly straight to ``waypoint`` at ``speed`` (m/s) with dt sub-steps.

        Stops early on a collision (counted; the drone stays at its last free position) or, when
        ``replan_distance`` is given, once a LiDAR scan taken in flight every ``scan_every``
        sub-steps shows an obstacle within that distance (the original's "obstacle_detected"
        replan). ``on_scan(scan, position)`` sees every in-flight scan. On a collision the
        returned flight's ``contact`` is the touched point.
        """
        c = self.config
        v = c.speed if speed is None else float(speed)
        start = self.position.copy()
        goal = np.asarray(waypoint, float)
        delta = goal - start
        length = float(np.linalg.norm(delta))
        n = max(1, int(np.ceil(length / (v * c.dt))))
        path = [start.copy()]
        collided = replanned = False
        t0 = self.time
        min_clear = np.inf
        touched = None
        k = 0
        for k in range(1, n + 1):
            nxt = start + delta * (k / n)
            if self.contact(nxt):
                self.collisions += 1
                collided = True
                touched = self.last_contact.copy()
                if c.end_on_collision:
                    self.crashed = True
                self.time += c.dt
                break
            self.position = nxt
            self.time += c.dt
            path.append(nxt.copy())
            if replan_distance is not None and k % scan_every == 0 and k < n:
                s = self.scan(nxt)
                min_clear = min(min_clear, s.min_range)
                if on_scan is not None:
                    on_scan(s, nxt)
                if s.min_range < replan_distance:
                    replanned = True
                    break
        self._place(self.position)
        self.path.extend(path[1:])
        reached = (not collided and not replanned and k == n)
        return Flight(start, self.position.copy(), reached, collided, replanned, self.time - t0,
                      np.array(path), float(min_clear), touched)

    def advance(self, seconds: float) -> None:
        """Let the clock run (hovering, e.g. while a planning call is served)."""
        self.time += float(seconds)


def make_drone_sim(field_seed: int = 0, end_on_collision: bool = False, **overrides) -> DroneSim:
    cfg = DroneConfig(end_on_collision=end_on_collision, **overrides)
    return DroneSim(field_seed, cfg)

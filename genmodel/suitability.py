"""The drone's observation pipeline and suitability state, as pure numpy functions.

Hierarchical active-inference drone (DRONE.md 2.2-2.3; the published code at commit e98ed45):
LiDAR hits are binned into 0.15 m voxels, a voxel holding enough points is an obstacle, and the
state's suitability combines the clearance to the nearest obstacle with the local obstacle density.

Minimum points per voxel. The original scanner (AirSim, 4000 points/s, 10 rotations/s) asked for
>= 2 points per 0.15 m voxel. Our LiDAR casts 16 channels x 25 azimuths = 400 rays per scan, so
neighbouring azimuths are 14.4 deg apart and neighbouring channels 1.33 deg apart: at 2 m range
two rays land 0.05 m apart vertically (the same voxel is possible) but at 7 m they are 0.16 m
apart, more than a voxel. With ``min_points=2`` every obstacle beyond about 6 m would vanish from a
single scan, so we use ``min_points=1`` (every hit is an obstacle voxel; a LiDAR return in pybullet
is exact, so there is no speckle noise for the threshold to reject). :data:`MIN_POINTS` states it.
"""

from __future__ import annotations

import numpy as np

VOXEL_SIZE = 0.15  # m (DRONE.md 2.2)
MIN_POINTS = 1  # points per voxel for an obstacle, see the module docstring
NO_OBSTACLE_CLEARANCE = 10.0  # m: clearance reported when no obstacle is sensed
DENSITY_RADIUS = 5.0  # m: state density counts obstacles within this radius
WAYPOINT_DENSITY_RADIUS = 3.0  # m: per-waypoint density (simulate_transition)
WAYPOINT_DENSITY_VOLUME = 113.1  # m^3 = 4/3 pi 3^3, as the original divides
BLOCKED_PATH = 0.5  # m: a straight path this close to a voxel is blocked (drone radius 0.25 m plus a margin)

# suitability constants (Planning module at e98ed45)
W_OBSTACLE = 0.8
W_DENSITY = 0.4
SAFETY_CENTRE = 3.0
SAFETY_SLOPE = 4.0
DENSITY_CENTRE = 0.15
DENSITY_SLOPE = 12.0


def voxelise(points, voxel: float = VOXEL_SIZE, min_points: int = MIN_POINTS) -> np.ndarray:
    """Obstacle voxels from world-frame LiDAR hits (N, 3): centroids of the points of every voxel
    holding at least ``min_points`` points, shape (M, 3)."""
    pts = np.asarray(points, float).reshape(-1, 3)
    if voxel <= 0:
        raise ValueError(f"voxelise: voxel size must be positive, got {voxel}")
    if min_points < 1:
        raise ValueError(f"voxelise: min_points must be >= 1, got {min_points}")
    if len(pts) == 0:
        return np.zeros((0, 3))
    ijk = np.floor(pts / voxel).astype(np.int64) + (1 << 20)  # +-157 km at 0.15 m fits 21 bits
    keys = (ijk[:, 0] << 42) | (ijk[:, 1] << 21) | ijk[:, 2]
    _, inv, counts = np.unique(keys, return_inverse=True, return_counts=True)
    inv = inv.reshape(-1)
    sums = np.zeros((len(counts), 3))
    np.add.at(sums, inv, pts)
    keep = counts >= min_points
    return sums[keep] / counts[keep, None]


def clearance(position, voxels, default: float = NO_OBSTACLE_CLEARANCE) -> float:
    """d_obs: distance from ``position`` to the nearest obstacle voxel, ``default`` (10 m) if none."""
    v = np.asarray(voxels, float).reshape(-1, 3)
    if len(v) == 0:
        return float(default)
    return float(np.sqrt(((v - np.asarray(position, float)) ** 2).sum(1)).min())


def density(position, voxels, radius: float = DENSITY_RADIUS) -> float:
    """rho = #obstacle voxels within ``radius`` / (4/3 pi radius^3), obstacles per m^3 (not bounded
    to [0, 1]; DRONE.md 2.2)."""
    v = np.asarray(voxels, float).reshape(-1, 3)
    n = int((((v - np.asarray(position, float)) ** 2).sum(1) <= radius * radius).sum()) if len(v) else 0
    return n / (4.0 / 3.0 * np.pi * radius ** 3)


def suitability(d, rho):
    """Suitability S in [0, 1] from clearance ``d`` (m) and density ``rho`` (DRONE.md 2.3, exact).

    S = clamp((w_o safety + w_d dens) / (w_o + w_d), 0, 1), safety = sigma(4 (d - 3)),
    dens = 1 / (1 + exp(12 (rho - 0.15))); overrides before combining: d < 1.2 scales safety by
    (d / 1.2)^2, rho > 0.4 scales dens by max(0.2, 1 - 2 (rho - 0.4)). Vectorised over arrays.
    """
    d = np.asarray(d, float)
    rho = np.asarray(rho, float)
    safety = 1.0 / (1.0 + np.exp(-SAFETY_SLOPE * (d - SAFETY_CENTRE)))
    safety = np.where(d < 1.2, safety * (d / 1.2) ** 2, safety)
    dens = 1.0 / (1.0 + np.exp(DENSITY_SLOPE * (rho - DENSITY_CENTRE)))
    dens = np.where(rho > 0.4, dens * np.maximum(0.2, 1.0 - 2.0 * (rho - 0.4)), dens)
    s = np.clip((W_OBSTACLE * safety + W_DENSITY * dens) / (W_OBSTACLE + W_DENSITY), 0.0, 1.0)
    return float(s) if s.ndim == 0 else s


def _sq_dists(A, V) -> np.ndarray:
    """Squared distances (N, M) between rows of A and V, by the |a|^2 + |v|^2 - 2 a.v expansion."""
    return np.maximum((A * A).sum(1)[:, None] + (V * V).sum(1)[None, :] - 2.0 * A @ V.T, 0.0)


def segments_clear(starts, end, voxels, margin: float = 1.5) -> np.ndarray:
    """Per start point (N, 3): True when no voxel lies within ``margin`` of the segment start -> end
    (the 'direct path is clear' test of simulate_transition)."""
    A = np.asarray(starts, float).reshape(-1, 3)
    v = np.asarray(voxels, float).reshape(-1, 3)
    if len(v) == 0 or len(A) == 0:
        return np.ones(len(A), bool)
    ab = np.asarray(end, float) - A  # (N, 3)
    L2 = np.maximum((ab * ab).sum(1), 1e-12)
    proj = v @ ab.T - (A * ab).sum(1)[None, :]  # (M, N): (v - a).ab
    t = np.clip(proj / L2[None, :], 0.0, 1.0)
    d2 = _sq_dists(A, v).T - 2.0 * t * proj + t * t * L2[None, :]  # |v - a - t ab|^2
    return (d2 > margin * margin).all(0)


def path_clearances(start, ends, voxels) -> np.ndarray:
    """Per end point (N, 3): the least distance from the straight segment ``start`` -> end to a voxel
    (inf without voxels). It is at most the clearance of either end."""
    B = np.asarray(ends, float).reshape(-1, 3)
    v = np.asarray(voxels, float).reshape(-1, 3)
    if len(v) == 0 or len(B) == 0:
        return np.full(len(B), np.inf)
    a = np.asarray(start, float)
    ab = B - a  # (N, 3)
    L2 = np.maximum((ab * ab).sum(1), 1e-12)
    va = v - a  # (M, 3)
    proj = va @ ab.T  # (M, N): (v - a).ab
    t = np.clip(proj / L2[None, :], 0.0, 1.0)
    d2 = (va * va).sum(1)[:, None] - 2.0 * t * proj + t * t * L2[None, :]  # |v - a - t ab|^2
    return np.sqrt(np.maximum(d2, 0.0).min(0))


def segment_clear(a, b, voxels, margin: float = 1.5) -> bool:
    """True when no voxel lies within ``margin`` of the segment a -> b."""
    return bool(segments_clear(np.asarray(a, float)[None], b, voxels, margin)[0])


def waypoint_suitability(waypoints, voxels, d_obs_now: float, target, position,
                         along_path: bool = False) -> np.ndarray:
    """Per-waypoint suitability as ``simulate_transition`` computes it (DRONE.md 2.3).

    Clearance d = min(current d_obs, min |waypoint - voxel|) (the current d_obs caps every
    candidate, a quirk kept on purpose); with ``along_path`` the clearance of the whole straight
    transition, min(current d_obs, :func:`path_clearances`), so a waypoint behind an obstacle the
    drone would fly through is not suitable (the published code looks at the two ends only), and a
    waypoint whose path passes within :data:`BLOCKED_PATH` of a voxel, closer than the drone is
    now, gets none of the near-target bonuses below (it cannot be reached). Density = #voxels
    within 3 m / 113.1 m^3, inflated by (1 + 0.5 max_octant / nearby) when more than 5 voxels are
    within 3 m and an octant holds more than 5 within 5 m (then d *= 0.85 if max_octant > 10 and
    d > 1.5). Near the target (< 10 m), waypoints that reduce the distance get +0.2 * proximity
    factor when the direct path is clear or the target is under 5 m away, and +0.3 (1 - d_tgt / 2)
    under 2 m. Returns S clipped to [0, 1].
    """
    W = np.asarray(waypoints, float).reshape(-1, 3)
    v = np.asarray(voxels, float).reshape(-1, 3)
    tgt = np.asarray(target, float)
    pos = np.asarray(position, float)
    n = len(W)
    d = np.full(n, float(d_obs_now))
    rho = np.zeros(n)
    reachable = np.ones(n, bool)
    if len(v):
        dist2 = _sq_dists(W, v)
        d = np.minimum(d, np.sqrt(dist2.min(1)))
        if along_path:
            along = path_clearances(pos, W, v)
            d = np.minimum(d, along)
            reachable = (along >= BLOCKED_PATH) | (along >= float(d_obs_now) - 1e-9)  # or no closer than now
        near3 = dist2 <= WAYPOINT_DENSITY_RADIUS ** 2
        nearby = near3.sum(1)
        rho = nearby / WAYPOINT_DENSITY_VOLUME
        rows, cols = np.nonzero(dist2 <= 25.0)
        dv = v[cols] - W[rows]
        octant = (dv[:, 0] > 0) * 4 + (dv[:, 1] > 0) * 2 + (dv[:, 2] > 0)
        max_oct = np.bincount(rows * 8 + octant, minlength=8 * n).reshape(n, 8).max(1)
        inflate = (nearby > 5) & (max_oct > 5)
        rho = np.where(inflate, rho * (1.0 + 0.5 * max_oct / np.maximum(nearby, 1)), rho)
        d = np.where(inflate & (max_oct > 10) & (d > 1.5), d * 0.85, d)
    s = np.asarray(suitability(d, rho), float).reshape(n)
    d_now = float(np.linalg.norm(tgt - pos))
    d_new = np.linalg.norm(tgt - W, axis=1)
    if d_now < 10.0:
        red = np.flatnonzero((d_new < d_now) & reachable)
        clear = segments_clear(W[red], tgt, v) if d_now >= 5.0 else np.ones(len(red), bool)
        for i, ok in zip(red, clear, strict=True):
            if ok:
                if d_now < 5.0:  # 1.5 plus directness terms under 5 m
                    step = W[i] - pos
                    to_t = tgt - pos
                    cosang = float(step @ to_t) / max(np.linalg.norm(step) * np.linalg.norm(to_t), 1e-9)
                    factor = 1.5 + 0.5 * max(cosang, 0.0)
                else:
                    factor = 1.0
                s[i] += 0.2 * factor
            if d_new[i] < 2.0:
                s[i] += 0.3 * (1.0 - d_new[i] / 2.0)
    return np.clip(s, 0.0, 1.0)

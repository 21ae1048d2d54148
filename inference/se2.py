"""Rigid 2-D transforms (SE(2)): rotation by ``yaw`` then translation by ``(x, y)``.

``T(p) = R(yaw) p + t``. Pure functions on a small NamedTuple, used to carry a pose
correction from one frame to another (e.g. the odometry frame to an agent's belief frame,
section 3.3 drift correction).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from cogmap.genmodel.numerics import wrap_angle


def rotation(yaw: float) -> np.ndarray:
    c, s = np.cos(yaw), np.sin(yaw)
    return np.array([[c, -s], [s, c]])


class SE2(NamedTuple):
    """``p -> R(yaw) p + (x, y)``; the identity is ``SE2()``."""

    yaw: float = 0.0
    x: float = 0.0
    y: float = 0.0

    @property
    def t(self) -> np.ndarray:
        return np.array([self.x, self.y])


def compose(a: SE2, b: SE2) -> SE2:
    """``a o b``: apply ``b`` first, then ``a``."""
    t = rotation(a.yaw) @ b.t + a.t
    return SE2(float(wrap_angle(a.yaw + b.yaw)), float(t[0]), float(t[1]))


def invert(a: SE2) -> SE2:
    """The transform that undoes ``a``."""
    t = -rotation(-a.yaw) @ a.t
    return SE2(float(wrap_angle(-a.yaw)), float(t[0]), float(t[1]))


def apply(a: SE2, points) -> np.ndarray:
    """Transform points ``(..., 2)``."""
    p = np.asarray(points, dtype=float)
    return p @ rotation(a.yaw).T + a.t


def rotate(a: SE2, vectors) -> np.ndarray:
    """Rotate direction vectors ``(..., 2)`` (no translation): points relative to a robot."""
    return np.asarray(vectors, dtype=float) @ rotation(a.yaw).T


def apply_pose(a: SE2, pose) -> np.ndarray:
    """Transform a pose ``(x, y, yaw)``; a 2-vector is treated as a position."""
    pose = np.asarray(pose, dtype=float)
    xy = apply(a, pose[:2])
    if pose.size < 3:
        return xy
    return np.array([xy[0], xy[1], float(wrap_angle(pose[2] + a.yaw))])


def about(yaw: float, centre, target) -> SE2:
    """The transform that rotates by ``yaw`` about ``centre`` and moves ``centre`` to ``target``:
    ``p -> R(yaw) (p - centre) + target``."""
    t = np.asarray(target, dtype=float) - rotation(yaw) @ np.asarray(centre, dtype=float)
    return SE2(float(wrap_angle(yaw)), float(t[0]), float(t[1]))


def fit(source, target, weights=None) -> SE2:
    """Least-squares rigid transform taking paired points ``source`` onto ``target`` (2-D Kabsch)."""
    p, q = np.asarray(source, dtype=float), np.asarray(target, dtype=float)
    w = np.ones(len(p)) if weights is None else np.asarray(weights, dtype=float)
    w = w / w.sum()
    mp, mq = w @ p, w @ q
    a, b = p - mp, q - mq
    h = (a * w[:, None]).T @ b  # cross-covariance
    yaw = float(np.arctan2(h[0, 1] - h[1, 0], h[0, 0] + h[1, 1]))
    t = mq - rotation(yaw) @ mp
    return SE2(yaw, float(t[0]), float(t[1]))


class Alignment(NamedTuple):
    transform: SE2  # takes the source points onto the target points
    inliers: float  # fraction of source points within ``tolerance`` of a target point
    rms: float  # root mean square distance of those inliers (m)


def icp(source, target, init: SE2 | None = None, iterations: int = 30, max_distance: float = 1.0,
        tolerance: float = 0.1) -> Alignment:
    """Align 2-D point sets (e.g. two LiDAR scans) by trimmed point-to-point ICP from ``init``.

    Pairs farther apart than a gate are ignored; the gate shrinks from ``max_distance`` to
    ``2 * tolerance`` over the first half of the iterations (it stops once the fit no longer
    moves), so a coarse start can converge and the final fit uses close pairs only."""
    from scipy.spatial import cKDTree

    init = SE2() if init is None else init
    src, tgt = np.asarray(source, dtype=float), np.asarray(target, dtype=float)
    if len(src) < 3 or len(tgt) < 3:
        return Alignment(init, 0.0, np.inf)
    tree = cKDTree(tgt)
    t = init
    shrink = max(iterations // 2, 1)
    gates = np.geomspace(max(max_distance, 2 * tolerance), 2 * tolerance, shrink)
    for i in range(iterations):
        gate = gates[min(i, shrink - 1)]
        d, k = tree.query(apply(t, src), distance_upper_bound=gate)
        ok = np.isfinite(d)
        if ok.sum() < 3:
            break
        new = fit(src[ok], tgt[k[ok]])
        step = abs(new.yaw - t.yaw) + abs(new.x - t.x) + abs(new.y - t.y)
        t = new
        if i >= shrink - 1 and step < 1e-6:  # converged at the final gate
            break
    d, _ = tree.query(apply(t, src))
    inside = d < tolerance
    rms = float(np.sqrt(np.mean(d[inside] ** 2))) if inside.any() else np.inf
    return Alignment(t, float(inside.mean()), rms)

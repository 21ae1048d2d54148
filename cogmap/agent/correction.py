"""Drift correction by place recognition (section 3.3, Figure 6).

The believed pose is the odometry pose mapped by a rigid transform ``frame`` (odometry frame ->
belief frame, yaw + translation; :mod:`cogmap.inference.se2`). When a state is first visited
confidently the agent keeps an :class:`Anchor`: where it believed it was, its panorama turned to
the belief frame and its LiDAR returns in the belief frame. On a later confident visit of that
state, :func:`relocalise` compares what is sensed now with the anchor:

1. heading: the circular column shift that best aligns the panorama with the anchor's
   (:func:`cogmap.agent.encoder.best_shift`, within ``max_shift`` columns) gives the heading
   error of the belief frame (one column = 360 / width degrees on average: the four views are
   pinhole images, so a roll matches a turn only approximately, SSIM about 0.8 after a 17 degree
   turn is undone, 0.9 after 6 degrees);
2. position: the scan is aligned with the anchor's scan by ICP started from that heading;
3. recognition (observation evidence agrees with the state posterior): the shifted SSIM and the
   fraction of LiDAR returns that the aligned scans share must pass thresholds, and the
   correction must be small enough to be drift since the last correction.

Revisits alone leave the map made between them as drifted as the odometry was (Figure 6 case 1:
internally consistent, physically off). At a first visit, :func:`track` therefore aligns the
scan with the anchor of the state just left (one step away, still in LiDAR view), so new anchors
are laid down in a corrected frame. The paper names such a geometric back-end as future work
(section 5.1); ``AgentConfig(track_anchors=False)`` keeps only the paper's revisit correction.
Measured in the aisle warehouse, 5 seeds, study protocol: revisits only reduce the ATE/m from
0.073 to 0.060 (moderate) and 0.102 to 0.073 (severe); with tracking the belief ATE/m is 0.001-0.004.

Thresholds (``AgentConfig``), chosen from ``python bench/relocalisation.py`` (aisle warehouse,
150-step random walk, seed 0, the study's moderate and severe drift; quantiles 10/50/90 %):

- shift-searched SSIM of revisits within 0.25 m: 0.48/0.60/0.68 (moderate), 0.49/0.66/0.76
  (severe), 0.84/0.89/1.00 without drift; of places 0.25-1 m apart 0.44-0.48 / 0.50-0.62 /
  0.58-0.71; of places >= 3 m apart 0.43-0.45 / 0.49-0.51 / 0.56-0.66. Under drift SSIM alone
  cannot tell a revisit from another place, so it is only a gate: ``relocalise_align_ssim = 0.5``
  drops about half of the other places and keeps about 80 % of the drifted revisits.
- the column shift found for drifted revisits within 0.25 m lies 2-3 columns (3-4 degrees)
  from the true heading difference (median; 90 %: 4-7 columns), which is close enough for ICP.
- ICP from that heading (pairs whose heading difference lies within the search): revisits within
  0.5 m share 0.78-0.95 of their returns (median; 10 %: 0.02-0.58 when ICP fails) and the
  corrected position is within 0.01-0.02 m (median; 90 %: 0.04-0.32 m). Places >= 3 m apart share
  0.31-0.39 (median; 90 %: 0.87-0.92): with a 12 m LiDAR, scans a few metres apart overlap, and
  a high share means the relative pose was found, not that it is the same place. The correction
  uses that relative pose to the anchor, so ``relocalise_inliers = 0.7`` asks for a good
  alignment; ``relocalise_max_correction`` (influence radii) bounds what an aliased alignment
  (an aisle matched one rack further) could do.
- The same holds one step away, which :func:`track` uses at first visits (``track_inliers =
  0.5``, a gate of ``track_max_correction`` influence radii: one step of severe drift is about
  0.16 m and 6 degrees).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cogmap.genmodel.numerics import wrap_angle
from cogmap.inference.se2 import SE2, about, apply, icp

from .encoder import best_shift


@dataclass(frozen=True)
class Anchor:
    """What a state looked like at its first confident visit (belief frame)."""

    pose: np.ndarray  # believed (x, y)
    panorama: np.ndarray  # panorama turned to the belief frame
    scan: np.ndarray  # LiDAR returns relative to the robot, belief-frame orientation (n, 2)
    step: int


@dataclass(frozen=True)
class Relocalisation:
    """Outcome of one comparison with an anchor; ``correction`` maps belief-frame points as they
    were believed to where the anchor says they are."""

    accepted: bool
    correction: SE2
    ssim: float
    shift: int
    inliers: float


def panorama_columns(yaw: float, width: int) -> int:
    """Columns to roll a 360-degree panorama whose reference heading is off by ``-yaw``
    (views turning clockwise from the odometry heading): ``np.roll(p, panorama_columns(yaw, w),
    axis=1)`` shows the panorama as seen from a frame turned by ``yaw``."""
    return int(np.round(-wrap_angle(yaw) * width / (2 * np.pi)))


def to_frame_panorama(panorama: np.ndarray, yaw: float) -> np.ndarray:
    """The panorama as if rendered from a frame turned by ``yaw`` (odometry -> belief)."""
    k = panorama_columns(yaw, np.shape(panorama)[1])
    return panorama if k == 0 else np.roll(panorama, k, axis=1)


def track(anchor: Anchor, scan: np.ndarray, pose: np.ndarray, *, min_inliers: float,
          max_translation: float) -> Relocalisation:
    """Scan-only comparison with the anchor of a nearby state (the one just left, about one
    influence radius away, where panoramas no longer match but most LiDAR returns are shared):
    ICP from the believed pose with a gate of ``max_translation``."""
    pose = np.asarray(pose, dtype=float)[:2]
    a = icp(pose + scan, anchor.pose + anchor.scan, None, max_distance=max_translation)
    moved = float(np.hypot(*(apply(a.transform, pose) - pose)))
    ok = a.inliers >= min_inliers and moved <= max_translation
    return Relocalisation(bool(ok), a.transform, float("nan"), 0, a.inliers)


def relocalise(anchor: Anchor, panorama: np.ndarray, scan: np.ndarray, pose: np.ndarray, *, max_shift: int,
               min_ssim: float, min_inliers: float, max_translation: float) -> Relocalisation:
    """Compare the current view (belief frame) with ``anchor``; see the module docstring."""
    pose = np.asarray(pose, dtype=float)[:2]
    width = np.shape(panorama)[1]
    shift, score = best_shift(panorama, anchor.panorama, max_shift)
    yaw = -2 * np.pi * shift / width  # roll(p, s) lines up: the belief heading is s columns off
    init = about(yaw, pose, pose)
    a = icp(pose + scan, anchor.pose + anchor.scan, init, max_distance=max_translation)
    moved = float(np.hypot(*(apply(a.transform, pose) - pose)))
    turned = abs(float(wrap_angle(a.transform.yaw)))
    ok = (score >= min_ssim and a.inliers >= min_inliers and moved <= max_translation
          and turned <= 2 * np.pi * (max_shift + 2) / width)
    return Relocalisation(bool(ok), a.transform, score, shift, a.inliers)


def save_anchors(path, anchors: dict[int, Anchor]) -> None:
    """Write anchors to one compressed ``.npz`` (arrays only, no pickle)."""
    states = np.array(sorted(anchors), dtype=int)
    items = [anchors[int(s)] for s in states]
    scans = [np.asarray(a.scan, dtype=float).reshape(-1, 2) for a in items]
    np.savez_compressed(
        path, states=states, poses=np.array([a.pose for a in items], dtype=float).reshape(-1, 2),
        steps=np.array([a.step for a in items], dtype=int),
        panoramas=np.array([a.panorama for a in items]) if items else np.zeros((0, 1, 1)),
        scans=np.concatenate(scans) if scans else np.zeros((0, 2)),
        offsets=np.cumsum([0] + [len(s) for s in scans]))


def load_anchors(path) -> dict[int, Anchor]:
    """Anchors written by :func:`save_anchors`."""
    with np.load(path, allow_pickle=False) as f:
        off = f["offsets"]
        return {int(s): Anchor(f["poses"][i].copy(), f["panoramas"][i].copy(), f["scans"][off[i]:off[i + 1]].copy(),
                               int(f["steps"][i]))
                for i, s in enumerate(f["states"])}

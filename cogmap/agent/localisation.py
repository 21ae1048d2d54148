"""The AIMAPP agent's state and where it believes it is (section 3.3).

The state is three records: :class:`Belief` (the posterior, the belief frame, the lost test),
:class:`Counts` (steps and events) and :class:`Memory` (what the agent keeps of the places it has
been: anchors, states scanned from, moves driven, the sensed grid). The functions turn a reading
into the belief frame and test the drift corrections and re-localisations; each returns the new
frame (or None when nothing moves it) and leaves the state to the caller.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from cogmap.inference.se2 import SE2, apply, compose, rotate

from .config import AgentConfig
from .correction import Anchor, relocalise, to_frame_panorama, track
from .sensing import Sensed, blocked
from .viewmap import ViewMap


class Belief(NamedTuple):
    """Where the agent believes it is.

    Attributes
    ----------
    q : numpy.ndarray or None
        ``(num_states,)`` posterior over states after the last step (None before the first).
    frame : SE2
        Odometry frame -> belief frame (drift correction, section 3.3).
    lost : bool
        The lost test fired and the agent is re-localising.
    lost_evidence : float
        CUSUM statistic of conflict (A.1.2).
    last_obs : int or None
        Observation id of the last view.
    outcome : bool or None
        Reported outcome of the last real motion command (None: not reported yet).
    """

    q: np.ndarray | None
    frame: SE2
    lost: bool = False
    lost_evidence: float = 0.0
    last_obs: int | None = None
    outcome: bool | None = None


class Counts(NamedTuple):
    """Steps taken, accepted drift corrections, times lost and times found again."""

    steps: int = 0
    corrections: int = 0
    lost_events: int = 0
    relocalisations: int = 0


class Memory(NamedTuple):
    """What the agent keeps of the places it has been (containers updated in place).

    Attributes
    ----------
    anchors : dict of int to Anchor
        State -> view and scan of its first confident visit (drift correction).
    scanned : set of int
        States the agent has stood on with its LiDAR reporting.
    traversed : set of (int, int, int)
        ``(state, heading, state)`` moves the robot has driven (and their reverses): their way is
        known passable, so only an obstacle within the robot's own width blocks them.
    frame_moves : list of dict
        Every move of the belief frame: ``{"step", "kind", "moved_m"}``, kind ``"correction"`` or
        ``"relocalisation"``, ``moved_m`` how far the believed position of the robot moved (m).
    views : ViewMap
        What the LiDAR has sensed (exploration planning).
    """

    anchors: dict
    scanned: set
    traversed: set
    frame_moves: list
    views: ViewMap


def empty_memory(cfg: AgentConfig) -> Memory:
    """A :class:`Memory` with nothing in it."""
    return Memory({}, set(), set(), [], ViewMap(cfg))


def shifted(frame: SE2, delta) -> SE2:
    """``frame`` translated by ``delta`` (belief-frame metres)."""
    return compose(SE2(0.0, float(delta[0]), float(delta[1])), frame)


def to_belief(frame: SE2, cfg: AgentConfig, sensed: Sensed) -> Sensed:
    """``sensed`` in the belief frame: panorama turned (images only), LiDAR returns rotated
    and the per-heading obstacle flags recomputed from them (or, without a scan, taken from
    the nearest odometry heading)."""
    yaw = frame.yaw
    if yaw == 0.0:
        return sensed
    pano = sensed.panorama
    if pano is not None and np.ndim(pano) >= 2:
        pano = to_frame_panorama(pano, yaw)
    scan = None if sensed.scan is None else rotate(frame, sensed.scan)
    sweep = None if sensed.sweep is None else rotate(frame, sensed.sweep)
    if scan is not None:
        h = 2 * np.pi * np.arange(cfg.num_headings) / cfg.num_headings
        moves = cfg.influence_radius * np.stack([np.cos(h), np.sin(h)], axis=1)
        obstacles = blocked(scan, moves, cfg.robot_radius + cfg.obstacle_margin)
    elif sensed.obstacles is not None:
        k = int(np.round(yaw * cfg.num_headings / (2 * np.pi)))
        obstacles = np.roll(np.asarray(sensed.obstacles, dtype=bool), k)
    else:  # the LiDAR is silent
        obstacles = None
    return Sensed(pano, obstacles, sensed.odometry, sensed.moved, scan, sweep)


def corrected_frame(belief: Belief, anchors: dict, cfg: AgentConfig, q: np.ndarray, confident: bool, last,
                    local: Sensed, pose: np.ndarray) -> SE2 | None:
    """Drift correction (section 3.3), once per confident arrival at the state ``q`` names (not
    while lost, not without a scan): the place's anchor (its view and scan) or, on a first visit,
    the anchor of the place just left (its scan), aligned with the current reading
    (``correction.relocalise`` / ``track``). Returns the corrected frame, or None when nothing is
    recognised or the correction is within the alignment's own error."""
    if belief.lost or not confident or local.scan is None:
        return None
    state = int(np.argmax(q))
    last_state = None if last is None else last.state
    if last_state == state:
        return None  # compare once per arrival
    frame = belief.frame
    reach = cfg.relocalise_max_correction * cfg.influence_radius
    anchor = anchors.get(state)
    if anchor is not None and np.ndim(local.panorama) >= 2:  # a revisit: the place's own view and scan
        if np.hypot(*(pose - anchor.pose)) > cfg.influence_radius + reach:
            return None
        r = relocalise(anchor, np.asarray(local.panorama), local.scan, pose,
                       max_shift=cfg.relocalise_max_shift, min_ssim=cfg.relocalise_align_ssim,
                       min_inliers=cfg.relocalise_inliers, max_translation=reach)
    elif anchor is None and cfg.track_anchors and last_state is not None and last_state in anchors:
        # a first visit: the scan of the place just left is still in view
        r = track(anchors[last_state], local.scan, pose, min_inliers=cfg.track_inliers,
                  max_translation=cfg.track_max_correction * cfg.influence_radius)
    else:
        return None
    if not r.accepted:
        return None
    moved = float(np.hypot(*(apply(r.correction, pose) - pose)))
    if moved < cfg.min_correction and abs(r.correction.yaw) < cfg.min_correction_yaw:
        return None  # within the alignment's own error: keep the frame
    return compose(r.correction, frame)


def scan_agrees(anchors: dict, poses: np.ndarray, cfg: AgentConfig, scan: np.ndarray | None,
                pose: np.ndarray) -> bool:
    """The LiDAR scan aligns, within the tracking gate, with the anchor of the nearest
    anchored state around the believed pose (False without a scan or an anchor nearby)."""
    if scan is None or not anchors:
        return False
    states = np.fromiter(anchors, dtype=int)
    d = np.hypot(*(poses[states] - pose).T)
    k = int(np.argmin(d))
    if d[k] > 1.5 * cfg.influence_radius:
        return False
    r = track(anchors[int(states[k])], scan, pose, min_inliers=cfg.relocalise_inliers,
              max_translation=cfg.track_max_correction * cfg.influence_radius)
    return r.accepted


def found_frame(frame: SE2, anchor: Anchor | None, cfg: AgentConfig, state_pose: np.ndarray, sensed: Sensed,
                pose: np.ndarray) -> SE2 | None:
    """The frame that re-localises the agent on a state after being lost, or None.
    With the state's anchor and a scan, the view (heading) and the scan (position) must
    align with it, as in :func:`correction.relocalise` from the anchor's pose; otherwise the
    belief moves onto the state's stored pose ``state_pose``."""
    if anchor is None or sensed.scan is None or np.ndim(sensed.panorama) < 2:
        return shifted(frame, state_pose - pose)  # trust the map's pose
    r = relocalise(anchor, np.asarray(sensed.panorama), sensed.scan, anchor.pose,
                   max_shift=cfg.relocalise_max_shift, min_ssim=cfg.relocalise_align_ssim,
                   min_inliers=cfg.relocalise_inliers, max_translation=cfg.influence_radius)
    if not r.accepted:
        return None
    # move the believed pose onto the anchor's, then apply the alignment found from there
    return compose(compose(r.correction, SE2(0.0, *(anchor.pose - pose))), frame)

"""One drone planning step: candidates -> per-waypoint suitability -> filter -> EFE -> shaping ->
ranking -> the top K actions (DRONE.md 2.5-2.6). The first action is flown (receding horizon).

:func:`plan_waypoints` is a pure function of its inputs (plus the seeded generator for the
target-biased candidates). Beliefs enter through ``entropy_sum`` = H_d + H_az + H_el of the kernel
beliefs (computed by the caller with the ``"kernel"`` inference scheme).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from cogmap.genmodel.suitability import segments_clear, waypoint_suitability

from . import drone_efe as E
from .drone_waypoints import (
    candidate_waypoints,
    filter_waypoints,
    policy_length,
    waypoint_count,
    waypoint_radius,
)


@dataclass(frozen=True)
class DronePlannerConfig:
    """``use_filter=False`` is the no-suitability-filter ablation (every candidate is ranked);
    ``w_epistemic=0`` the no-epistemic ablation.

    Three switches differ from the published planner (``False`` gives its behaviour, see
    :meth:`published`): ``novelty`` discounts the EFE of a candidate by the novelty of its place
    (inhibition of return, kernel width ``novelty_width`` metres); ``path_clearance`` takes a
    candidate's clearance along its whole straight path, not at its two ends; ``keep_ties`` lets the
    fallback cascade keep every candidate tied for its last place, so the EFE ranking picks among
    them."""

    use_filter: bool = True
    w_pragmatic: float = E.W_PRAGMATIC
    w_epistemic: float = E.W_EPISTEMIC
    tau: float = E.TAU
    min_step: float = 1.0  # returned actions are at least this long (m)
    min_altitude: float = 1.0  # candidates below are inside the ground
    voxel_horizon: float = 5.0  # voxels farther than radius + this cannot change a candidate
    novelty: bool = True  # False: the paper's EFE; True: it decays at visited places
    novelty_width: float = E.NOVELTY_WIDTH  # m: kernel width of one visit
    path_clearance: bool = True  # False: clearance at the waypoint (and the drone) only, as published
    keep_ties: bool = True  # False: the fallback takes the first of equally suitable candidates, as published

    @classmethod
    def published(cls, **changes) -> DronePlannerConfig:
        """The published planner: novelty, path clearance and tie keeping off.

        Parameters
        ----------
        **changes
            Further fields to set.

        Returns
        -------
        DronePlannerConfig
        """
        return cls(**{"novelty": False, "path_clearance": False, "keep_ties": False, **changes})


@dataclass
class PlanResult:
    actions: np.ndarray  # (K, 3) waypoints, best first
    scores: np.ndarray  # ranking scores of the returned waypoints
    efe: np.ndarray  # shaped EFE of the returned waypoints
    suitability: np.ndarray  # per-waypoint S of the returned waypoints
    radius: float
    n_candidates: int  # generated (with the ring's repeated up/down points)
    n_kept: int  # distinct candidates that passed the filter
    rule: str  # which filter rule kept the candidates
    efe_us_per_candidate: float  # microseconds of the EFE (preference, EFE, shaping) per candidate


class DroneScene(NamedTuple):
    """What the drone plans from: the ``model`` argument of the ``"drone"`` planner
    (:func:`cogmap.planning.drone_lookahead.drone_planner`).

    Attributes
    ----------
    position, target : numpy.ndarray
        ``(3,)`` metres, world frame.
    voxels : numpy.ndarray
        ``(M, 3)`` obstacle voxel centres the drone perceives, metres.
    clearance, density, suitability : float
        The current ``d_obs`` (m), ``rho`` and ``S``.
    d_start : float
        Distance to the target at the start of the episode (journey bonus), metres.
    visited : numpy.ndarray
        ``(K, 3)`` positions of the episode's earlier decisions (novelty).
    config : DronePlannerConfig
        Planner settings.
    """

    position: np.ndarray
    target: np.ndarray
    voxels: np.ndarray
    clearance: float
    density: float
    suitability: float
    d_start: float
    visited: np.ndarray
    config: DronePlannerConfig


def plan_waypoints(position, target, voxels, d_obs: float, rho: float, s_now: float, entropy_sum: float,
                   d_start: float, rng: np.random.Generator, config: DronePlannerConfig | None = None,
                   visited=None, objective=None) -> PlanResult:
    """The planning step; see the module docstring. ``voxels`` are obstacle voxel centres (M, 3),
    ``d_obs``, ``rho``, ``s_now`` the current clearance, density and suitability, ``d_start`` the
    distance to the target at the start of the episode (journey bonus), ``visited`` the positions
    (K, 3) of the earlier decisions of the episode (the novelty of the epistemic term; none: every
    candidate is novel), ``objective`` the EFE (:func:`~.drone_efe.drone_objective`; default built
    from the config's two weights)."""
    cfg = config or DronePlannerConfig()
    pos = np.asarray(position, float)
    tgt = np.asarray(target, float)
    d_now = float(np.linalg.norm(tgt - pos))
    r = waypoint_radius(s_now, rho, d_obs, d_now)
    n = waypoint_count(s_now, rho, d_obs, d_now)
    W = candidate_waypoints(pos, tgt, r, n, rng, cfg.min_altitude)
    n_generated = len(W)
    # the ring's +-pi/2 rows repeat the straight-up and straight-down points (a quirk of the
    # original): score each point once; repeated points would only tie with themselves
    _, first = np.unique(W.round(9), axis=0, return_index=True)
    W = W[np.sort(first)]
    V = np.asarray(voxels, float).reshape(-1, 3)
    if len(V):
        V = V[((V - pos) ** 2).sum(1) <= (r + cfg.voxel_horizon) ** 2]
    S = waypoint_suitability(W, V, d_obs, tgt, pos, along_path=cfg.path_clearance)
    if cfg.use_filter:
        keep, rule = filter_waypoints(W, S, pos, tgt, rho, path_clear=lambda idx: segments_clear(W[idx], tgt, V),
                                      keep_ties=cfg.keep_ties)
    else:
        keep, rule = np.arange(len(W)), "no filter"
    W, S = W[keep], S[keep]
    t0 = time.perf_counter()
    a = W - pos
    mag = np.linalg.norm(a, axis=1)
    d_new = np.linalg.norm(tgt - W, axis=1)
    heading = np.arctan2(a[:, 1], a[:, 0])
    pitch = np.arctan2(a[:, 2], np.hypot(a[:, 0], a[:, 1]))
    to_t = tgt - W
    az = np.arctan2(to_t[:, 1], to_t[:, 0]) - heading
    az = np.arctan2(np.sin(az), np.cos(az))
    el = np.arctan2(to_t[:, 2], np.hypot(to_t[:, 0], to_t[:, 1])) - pitch
    pref = E.preference(d_new, az, el, S, cfg.tau)
    eta = E.novelty(W, visited, cfg.novelty_width) if cfg.novelty else 1.0
    G, _, _ = E.efe(pref, E.distance_bonus(d_now, d_new), mag, entropy_sum, cfg.w_pragmatic, cfg.w_epistemic, eta,
                    objective)
    G = E.shape(G, S, d_now, d_new, mag, rho, d_obs, d_start)
    efe_us = 1e6 * (time.perf_counter() - t0) / max(len(W), 1)
    long_enough = np.flatnonzero(mag >= cfg.min_step)
    pool = long_enough if len(long_enough) else np.arange(len(W))
    score, order = E.rank(S[pool], G[pool], s_now)
    k = max(1, policy_length(s_now))
    top = pool[order[:k]]
    return PlanResult(W[top], score[order[:k]], G[top], S[top], r, n_generated, int(len(W)), rule, efe_us)

"""Adaptive waypoint generation and suitability filtering for the drone (DRONE.md 2.6).

Pure functions: the radius and count of candidate waypoints from the current suitability S,
density rho and clearance d_obs; the candidates (a ring plus target-biased steps); the filter with
the 0.75 / 0.6 thresholds and its fallback cascade 0.4 / 0.3 / 0.2 / argmax.
"""

from __future__ import annotations

import numpy as np

THRESHOLD = 0.75
THRESHOLD_NEAR = 0.6  # within NEAR_TARGET of the target
NEAR_TARGET = 10.0
FAR_TARGET = 20.0
FALLBACK = (0.4, 0.3, 0.2)


def waypoint_radius(s: float, rho: float, d_obs: float, d_tgt: float) -> float:
    """r = 1 + 2.5 S, at least 1 + 0.5 (1 - env) with env = mean(clamp(1 - 5 rho, 0.3, 1),
    clamp(d_obs / 10, 0.3, 1)); r >= 1.1 d_tgt within 10 m of the target; r >= 2 beyond 20 m."""
    env = 0.5 * (np.clip(1.0 - 5.0 * rho, 0.3, 1.0) + np.clip(d_obs / 10.0, 0.3, 1.0))
    r = max(1.0 + 2.5 * s, 1.0 + 0.5 * (1.0 - env))
    if d_tgt < NEAR_TARGET:
        r = max(r, 1.1 * d_tgt)
    if d_tgt > FAR_TARGET:
        r = max(r, 2.0)
    return float(r)


def waypoint_count(s: float, rho: float, d_obs: float, d_tgt: float) -> int:
    """N = 100 - 75 S; times max(clamp(10 rho, 1, 3), clamp(5 / max(d_obs, 1), 1, 2.5)) when
    rho > 0.1 or d_obs < 5 (times 1.2 more if both); times 1.2 beyond 20 m or 1.1 within 10 m of the
    target; clamped to [25, 100]."""
    n = 100.0 - 75.0 * s
    dense, close = rho > 0.1, d_obs < 5.0
    if dense or close:
        n *= max(np.clip(10.0 * rho, 1.0, 3.0), np.clip(5.0 / max(d_obs, 1.0), 1.0, 2.5))
        if dense and close:
            n *= 1.2
    if d_tgt > FAR_TARGET:
        n *= 1.2
    elif d_tgt < NEAR_TARGET:
        n *= 1.1
    return int(np.clip(round(n), 25, 100))


def policy_length(s: float) -> int:
    """K = round(5 - 3 S): how many ranked actions a planning call returns."""
    return int(round(5.0 - 3.0 * s))


def _direction(az, el):
    return np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], -1)


def candidate_waypoints(position, target, radius: float, n: int, rng: np.random.Generator,
                        min_altitude: float = 1.0) -> np.ndarray:
    """Candidates (M, 3): 70 % ring = round(0.7 n) azimuths x elevations {-pi/2, 0, pi/2} at the
    radius (the +-pi/2 rows collapse to repeated straight up/down points, as in the original), 30 %
    target-biased = one direct step of min(r, 0.8 d_tgt) and rotations of the target direction by
    up to +-30 deg in yaw, +-30 deg in pitch, or +-15 deg in both, steps U[0.2 r, r] floored at
    max(1, 0.75 r). Waypoints below ``min_altitude`` (inside the ground) are dropped."""
    pos = np.asarray(position, float)
    tgt = np.asarray(target, float)
    n_ring = int(round(0.7 * n))
    az = 2 * np.pi * np.arange(n_ring) / max(n_ring, 1)
    A, E = np.meshgrid(az, np.array([-np.pi / 2, 0.0, np.pi / 2]), indexing="ij")
    ring = pos + radius * _direction(A.ravel(), E.ravel())
    to_t = tgt - pos
    d_tgt = float(np.linalg.norm(to_t))
    az_t = float(np.arctan2(to_t[1], to_t[0]))
    el_t = float(np.arctan2(to_t[2], np.hypot(to_t[0], to_t[1])))
    direct = pos + min(radius, 0.8 * d_tgt) * _direction(np.array(az_t), np.array(el_t))
    m = max(n - n_ring - 1, 0)
    groups = np.arange(m) % 3
    yaw = np.where(groups == 0, rng.uniform(-30, 30, m), np.where(groups == 2, rng.uniform(-15, 15, m), 0.0))
    pitch = np.where(groups == 1, rng.uniform(-30, 30, m), np.where(groups == 2, rng.uniform(-15, 15, m), 0.0))
    steps = np.maximum(rng.uniform(0.2 * radius, radius, m), max(1.0, 0.75 * radius))
    biased = pos + steps[:, None] * _direction(az_t + np.deg2rad(yaw), el_t + np.deg2rad(pitch))
    W = np.vstack([ring, direct[None], biased])
    return W[W[:, 2] >= min_altitude]


def _best(idx, S, k: int | None, keep_ties: bool) -> np.ndarray:
    """The ``k`` (all if None) indices of ``idx`` with the highest S, best first; with ``keep_ties``
    also every other index whose S equals the k-th best (an argmax over a tie is the whole tie)."""
    idx = idx[np.argsort(-S[idx], kind="stable")]
    if k is None or len(idx) <= k:
        return idx
    if keep_ties:
        return idx[S[idx] >= S[idx[k - 1]] - 1e-12]
    return idx[:k]


def filter_waypoints(W, S, position, target, rho_now: float, path_clear=None,
                     keep_ties: bool = False) -> tuple[np.ndarray, str]:
    """Indices of the waypoints kept by the suitability filter and the rule that kept them.

    1. keep S >= 0.75 (0.6 within 10 m of the target);
    2. prioritise S > 0.8, plus S > 0.7 that reduce the distance; pad to 5 with the best others kept
       (when rho > 0.3 only waypoints with a clear path and d' < 1.2 d count);
    3. add up to 8 more that reduce the distance by at least 5 %;
    4. if none pass: the top 3 above 0.4, else 0.3, else 0.2, else the argmax of S.
    ``path_clear(indices) -> bool array`` tells whether those waypoints' direct paths to the target
    are clear (only asked when rho > 0.3). With ``keep_ties`` the fallback keeps every waypoint tied
    with its third best (or its best), so the EFE ranking, not the candidates' order, picks among
    equally suitable waypoints; the published code takes the first ones (when the current clearance
    caps every candidate, these are the ring's first, straight-down, points).
    """
    W = np.asarray(W, float)
    S = np.asarray(S, float)
    pos, tgt = np.asarray(position, float), np.asarray(target, float)
    d_now = float(np.linalg.norm(tgt - pos))
    d_new = np.linalg.norm(tgt - W, axis=1)
    reduces = d_new < d_now
    thr = THRESHOLD_NEAR if d_now < NEAR_TARGET else THRESHOLD
    passed = np.flatnonzero(S >= thr)
    if len(passed):
        if rho_now > 0.3:
            ok = passed[d_new[passed] < 1.2 * d_now]
            if path_clear is not None and len(ok):
                ok = ok[np.asarray(path_clear(ok), bool)]
            if len(ok):
                passed = ok
        is_pri = (S[passed] > 0.8) | ((S[passed] > 0.7) & reduces[passed])
        pri, rest = passed[is_pri], passed[~is_pri]
        rest = rest[np.argsort(-S[rest], kind="stable")]
        chosen = np.concatenate([pri, rest[:max(0, 5 - len(pri))]])
        others = np.setdiff1d(passed, chosen)
        others = others[d_new[others] <= 0.95 * d_now]
        chosen = np.concatenate([chosen, others[np.argsort(d_new[others], kind="stable")][:8]])
        return np.unique(chosen).astype(int), f"threshold {thr}"
    for t in FALLBACK:
        idx = np.flatnonzero(S >= t)
        if len(idx):
            return _best(idx, S, 3, keep_ties), f"fallback {t}"
    return _best(np.arange(len(S)), S, 1, keep_ties), "fallback argmax"

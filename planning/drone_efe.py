"""Preferences, expected free energy, shaping and ranking of drone waypoints (DRONE.md 2.5).

All functions are vectorised over candidates. EFE is negative (lower is better); shaping multiplies
it by factors >= 1, so a larger factor favours a candidate.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .efe import Objective

MAX_DISTANCE = 125.0
W_PRAGMATIC = 1.0  # ActionPlanner defaults of the paper
W_EPISTEMIC = 0.2
TAU = 0.4  # suitability threshold of the preference: the server's safety_margin / 5 with a 2 m margin
NOVELTY_WIDTH = 1.0  # m: kernel width of a visit (the shortest step a planning call returns)


def distance_preference(d):
    """pref_d = (1 - min(d / 125, 1))^2 exp(-0.05 d)."""
    d = np.asarray(d, float)
    return (1.0 - np.minimum(d / MAX_DISTANCE, 1.0)) ** 2 * np.exp(-0.05 * d)


def angle_preference(theta):
    """pref_ang = 0.2 + 0.8 ((cos|theta| + 1) / 2)^3."""
    return 0.2 + 0.8 * ((np.cos(np.abs(np.asarray(theta, float))) + 1.0) / 2.0) ** 3


def suitability_preference(s, tau: float = TAU):
    """pref_S = S^2 / (2 tau) below tau, else 0.5 + 0.5 (S - tau) / (1 - tau)."""
    s = np.asarray(s, float)
    return np.where(s < tau, s ** 2 / (2 * tau), 0.5 + 0.5 * (s - tau) / (1 - tau))


def preference(d, azimuth, elevation, s, tau: float = TAU):
    """Combined preference (w_d pref_d + 0.5 pref_ang + w_s pref_S) / (w_d + 0.5 + w_s), w_d = 2,
    w_s = 1; below S = 0.4, with f = 2.5 (0.4 - S): w_d = max(2 (1 - f / 2), 0.5), w_s = 1 + f."""
    s = np.asarray(s, float)
    f = np.where(s < 0.4, 2.5 * (0.4 - s), 0.0)
    wd = np.where(s < 0.4, np.maximum(2.0 * (1.0 - f / 2.0), 0.5), 2.0)
    ws = 1.0 + f
    pa = 0.5 * (angle_preference(azimuth) + angle_preference(elevation))
    return (wd * distance_preference(d) + 0.5 * pa + ws * suitability_preference(s, tau)) / (wd + 0.5 + ws)


def distance_bonus(d_now: float, d_new):
    """Relative progress max(0, (d - d') / d): the paper names a 'distance bonus' beside the
    preference without its formula; this is our reading (a bonus for getting closer)."""
    return np.maximum(0.0, (d_now - np.asarray(d_new, float)) / max(d_now, 1e-9))


def visit_counts(waypoints, visited, width: float = NOVELTY_WIDTH):
    """Kernel visit counts n(w) = sum_k exp(-|w - p_k|^2 / (2 width^2)) of waypoints ``(M, 3)`` over
    the positions ``visited`` ``(K, 3)`` (zeros without visits)."""
    W = np.asarray(waypoints, float).reshape(-1, 3)
    P = np.asarray(visited, float).reshape(-1, 3) if visited is not None else np.zeros((0, 3))
    if len(P) == 0 or len(W) == 0:
        return np.zeros(len(W))
    d2 = ((W[:, None, :] - P[None, :, :]) ** 2).sum(-1)
    return np.exp(-0.5 * d2 / (width * width)).sum(1)


def novelty(waypoints, visited, width: float = NOVELTY_WIDTH, prior_count: float = 1.0):
    """Novelty eta(w) = a0 / (a0 + n(w)) in (0, 1] of each waypoint: 1 where the drone has not been,
    halved by one visit, decaying as 1 / n with more (the information still to gain about a place
    whose Dirichlet visit count is a0 + n; a0 = ``prior_count``). See :func:`visit_counts`."""
    n = visit_counts(waypoints, visited, width)
    return prior_count / (prior_count + n)


class DroneStep(NamedTuple):
    """Step context of ``K`` candidate waypoints for the drone's EFE terms.

    Attributes
    ----------
    preference : numpy.ndarray
        ``(K,)`` combined preference of each waypoint (:func:`preference`).
    bonus : numpy.ndarray
        ``(K,)`` distance bonus (:func:`distance_bonus`).
    magnitude : numpy.ndarray
        ``(K,)`` step length ``|a|`` (m) times the novelty ``eta`` of the waypoint (1 without novelty).
    entropy_sum : float
        ``H_d + H_az + H_el`` of the kernel beliefs (nats).
    """

    preference: np.ndarray
    bonus: np.ndarray
    magnitude: np.ndarray
    entropy_sum: float

    @property
    def num_candidates(self) -> int:
        return len(self.magnitude)


def drone_pragmatic(ctx: DroneStep) -> np.ndarray:
    """Pragmatic value ``(pref + bonus) |a| eta`` of each waypoint (DRONE.md 2.5)."""
    return (ctx.preference + ctx.bonus) * ctx.magnitude


def drone_epistemic(ctx: DroneStep) -> np.ndarray:
    """Epistemic value ``0.5 (H_d + H_az + H_el) |a| eta`` of each waypoint (DRONE.md 2.5)."""
    return 0.5 * ctx.entropy_sum * ctx.magnitude


def drone_objective(w_pragmatic: float = W_PRAGMATIC, w_epistemic: float = W_EPISTEMIC) -> Objective:
    """The drone's EFE as an :class:`~cogmap.planning.efe.Objective`:
    ``G = -w_prag drone_pragmatic - w_epi drone_epistemic`` per waypoint."""
    return Objective(((drone_pragmatic, float(w_pragmatic)), (drone_epistemic, float(w_epistemic))))


def efe(pref, bonus, magnitude, entropy_sum: float, w_pragmatic: float = W_PRAGMATIC,
        w_epistemic: float = W_EPISTEMIC, novelty=1.0, objective: Objective | None = None):
    """G = eta (-w_prag (pref + bonus) |a| - w_epi 0.5 (H_d + H_az + H_el) |a|); returns (G, pragmatic,
    epistemic). With ``novelty`` eta = 1 this is the paper's EFE: the entropies are the same for
    every candidate, so the epistemic term rewards step length. With eta < 1 (:func:`novelty`, per
    candidate) both terms decay at places already visited: the information still to gain there is
    smaller, and the preference for a predicted state is discounted by how often the drone has
    already been there (inhibition of return). The two parts are the terms of
    :func:`drone_objective` (``objective``, default built from the two weights)."""
    m = np.asarray(magnitude, float) * np.asarray(novelty, float)
    ctx = DroneStep(np.asarray(pref, float), np.asarray(bonus, float), m, float(entropy_sum))
    parts = (objective or drone_objective(w_pragmatic, w_epistemic)).breakdown(ctx)
    prag, epi = parts["drone_pragmatic"], parts["drone_epistemic"]
    return prag + epi, prag, epi


def journey_bonus(d_now: float, d_start: float):
    """Up to 3x in the last 10 % of the journey: 1 + 2 clip((f - 0.9) / 0.1, 0, 1), f = 1 - d / d0."""
    f = 1.0 - d_now / max(d_start, 1e-9)
    return 1.0 + 2.0 * float(np.clip((f - 0.9) / 0.1, 0.0, 1.0))


def shape(G, s, d_now: float, d_new, magnitude, rho_now: float, d_obs_now: float, d_start: float):
    """Shaping: x (1 + 2 S^2 clamp(2 rho, 0.5, 1.5)) when dense (rho > 0.1) or close (d_obs < 5),
    else x (1 + S); distance-reducing candidates also x progress bonus (1 + (d - d') / |a|, in
    [1, 2]) x (1 + 1.5 S) x journey bonus."""
    G = np.asarray(G, float)
    s = np.asarray(s, float)
    d_new = np.asarray(d_new, float)
    if rho_now > 0.1 or d_obs_now < 5.0:
        G = G * (1.0 + 2.0 * s ** 2 * np.clip(2.0 * rho_now, 0.5, 1.5))
    else:
        G = G * (1.0 + s)
    red = d_new < d_now
    progress = 1.0 + np.clip((d_now - d_new) / np.maximum(np.asarray(magnitude, float), 1e-9), 0.0, 1.0)
    mult = progress * (1.0 + 1.5 * s) * journey_bonus(d_now, d_start)
    return np.where(red, G * mult, G)


def ranking_weights(s_now: float) -> tuple[float, float]:
    """(w_S, w_E) = (0.7, 0.3) if S > 0.8, (0.6, 0.4) if S > 0.6, else (0.5, 0.5)."""
    if s_now > 0.8:
        return 0.7, 0.3
    if s_now > 0.6:
        return 0.6, 0.4
    return 0.5, 0.5


def rank(s, G, s_now: float):
    """Scores w_S S + w_E (1 - normalised G) (G scaled to [0, 1], best = lowest) and the order,
    best first."""
    G = np.asarray(G, float)
    span = float(G.max() - G.min()) if len(G) else 0.0
    g = (G - G.min()) / span if span > 1e-12 else np.zeros_like(G)
    ws, we = ranking_weights(s_now)
    score = ws * np.asarray(s, float) + we * (1.0 - g)
    return score, np.argsort(-score, kind="stable")

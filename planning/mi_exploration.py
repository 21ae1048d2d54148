"""Exploration by mutual information in DVBF-LM (paper Section VI, Appendices D-E).

Two stages (VI-C):

1. **Candidates** (Appendix E, Algorithm 2): an obstacle density is a histogram of the end points of
   the predicted LiDAR beams ``x_hat_n`` at the mean visited poses ``z_hat_n`` (the map mean read by the
   emission), normalised by ``N K_laser``; its log, shifted so free space costs 0 and bilinearly
   interpolated, is the obstacle penalty ``L_obstacle(z)``. ``F`` random control sequences are each
   optimised with Adam to minimise ``E_z [sum_t L_obstacle(z_t)]`` (Eq. 7/8) under the engineered
   transition from the current pose particles, plus an L2 term (weight 2.0, Appendix E-A) on the turn
   controls, our reading of the paper's "L2 regularisation ... applied to the resulting pose angles" so
   that trajectories do not circle in place.
2. **Score** (VI-B, Eq. 6): ``I(x_1:T; M) ~ H(X) - 1/M sum_m H(X | M_m)`` with the Kozachenko-Leonenko
   estimator of :mod:`.knn_entropy`, from ``L`` samples of the predictive marginal (a fresh map sample
   each) and ``K`` samples for each of ``M`` map samples ``M_m ~ q(M)``, all by ancestral sampling:
   poses through the transition, ranges ``N(mu_E(chart(M, z)), sigma_E^2)``.

The k-NN estimator cannot work in the 1,000 dimensions of 50 scans of 20 beams from 100 samples, so
the predicted scans are taken every ``obs_every`` steps and projected onto the ``dim`` leading principal
directions of all samples of that candidate before estimation. A fixed function of ``x`` cannot add
information (data processing inequality), so the score is a lower bound of ``I(x_1:T; M)``; the
projection keeps the directions in which the predictions vary most, which is where the map's
uncertainty shows.

Defaults are the paper's (Appendix D-B): horizon ``T = 50``, ``F = 40`` candidates, ``L = 30``,
``M = 40``, ``K = 100``; Appendix E-A optimises for 500 Adam steps at learning rate 1e-3 (on its own
control scale). Smaller values are arguments. Our additions to the procedure (:class:`MIConfig`:
``collision_level``, ``steer_only``, ``feasible_only``, ``scan_margin``; :func:`truncate_at_collision`,
:func:`scan_free_steps`) keep the agent moving in narrow corridors; ``feasible_only`` and the scan check
are on by default, ``steer_only`` is off (the study turns it on). Pure functions of arrays (jax for the model parts,
numpy for the estimator); nothing here imports the agent layer.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from cogmap.genmodel.charts import bilinear_read
from cogmap.genmodel.dvbf import DVBFConfig, kinematic_mean, predict_scan
from cogmap.genmodel.numerics import wrap_angle

from .knn_entropy import mutual_information


@dataclass(frozen=True)
class MIConfig:
    """Settings of one exploration planning call (paper Appendix D-B and E-A as defaults).

    ``horizon``: controls per candidate (T); ``n_candidates``: F; ``n_marginal``: L; ``n_maps``: M;
    ``n_per_map``: K; ``opt_iters``, ``opt_lr``: Adam on the obstacle penalty (on the raw, unsquashed
    controls); ``turn_reg``: L2 weight on the turns; ``max_turn``, ``max_step``: control bounds per
    step (the first turn of a candidate may be anything in [-pi, pi]); ``pose_samples``: rollouts in
    the penalty's expectation; ``obs_every``, ``dim``: scans used and projected dimension of the MI
    estimate; ``hist_cell``: side of the obstacle histogram's cells (world units); ``init_forward``: mean of
    the raw forward controls the candidates start from (``max_step * sigmoid(init_forward)``; 1.5 is 82 %
    of the largest step, 3.0 is 95 %); ``collision_level``: rise of the obstacle penalty above its value at
    the start that counts as a predicted collision (:func:`truncate_at_collision`; one beam end point in a
    histogram cell of 8,000 readings reads 0.81, a wall seen from every pose about 3-5); ``steer_only``: every
    forward step is ``max_step`` and only the turns are optimised (otherwise the optimiser also avoids
    walls by slowing down, and slow candidates win the MI score); ``feasible_only``: the argmax of the MI
    runs over the candidates with the longest collision-free prefix only (a candidate cut at a wall stands
    there, and standing still scores high); ``scan_margin``: also cut candidates where they come within this
    distance of a wall in the current scan (:func:`scan_free_steps`; None: off); ``pull_below``: when the best
    candidate's score is below this many nats, follow the way to the nearest frontier of the agent's own
    sensed grid instead (:mod:`.frontier_pull`; None: off, the paper's procedure), on a grid of ``pull_cell``
    cells where ``pull_hit_min`` returns make a wall and ``pull_min_crossed`` beams make a cell known.
    ``steer_only``, ``feasible_only``, ``scan_margin``, ``pull_below`` and the cut at collisions are our
    additions to the paper's procedure
    (:mod:`cogmap.dvbf.explore` says why)."""

    horizon: int = 50
    n_candidates: int = 40
    n_marginal: int = 30
    n_maps: int = 40
    n_per_map: int = 100
    opt_iters: int = 500
    opt_lr: float = 0.05
    turn_reg: float = 2.0
    max_turn: float = 0.35
    max_step: float = 0.01
    pose_samples: int = 4
    obs_every: int = 10
    dim: int = 4
    hist_cell: float = 0.02
    init_forward: float = 1.5
    collision_level: float = 0.5
    steer_only: bool = False
    feasible_only: bool = True
    scan_margin: float | None = 0.01
    pull_below: float | None = None
    pull_cell: float = 0.01
    pull_hit_min: int = 2
    pull_min_crossed: int = 3

    def __post_init__(self):
        if min(self.horizon, self.n_candidates, self.n_maps, self.pose_samples, self.obs_every, self.dim) < 1:
            raise ValueError(f"MIConfig: sizes must be >= 1, got {self}")
        if self.n_marginal < 3 or self.n_per_map < 3:
            raise ValueError("MIConfig: n_marginal and n_per_map must be >= 3 (k-NN needs neighbours)")
        if self.scan_margin is not None and self.scan_margin < 0:
            raise ValueError(f"MIConfig: scan_margin must be >= 0 or None, got {self.scan_margin}")
        if self.opt_iters < 0 or self.max_step <= 0 or self.max_turn <= 0 or self.hist_cell <= 0:
            raise ValueError(f"MIConfig: bad optimisation or control bounds in {self}")
        if self.pull_cell <= 0 or self.pull_hit_min < 1 or self.pull_min_crossed < 1:
            raise ValueError(f"MIConfig: pull_cell must be > 0, pull_hit_min and pull_min_crossed >= 1; got "
                             f"{self.pull_cell}, {self.pull_hit_min}, {self.pull_min_crossed}")


# -- obstacle penalty (Appendix E) ---------------------------------------------------------------

def beam_endpoints(poses, scans, lidar_range: float, hit_fraction: float = 0.97) -> np.ndarray:
    """World points ``(P, 2)`` where beams of ``scans (N, B)`` taken at ``poses (N, 3)`` end, for beams
    shorter than ``hit_fraction * lidar_range`` (longer ones hit nothing: ``f_laser`` of Appendix E)."""
    poses, scans = np.asarray(poses, float), np.asarray(scans, float)
    if poses.ndim != 2 or scans.ndim != 2 or len(poses) != len(scans) or poses.shape[1] != 3:
        raise ValueError(f"beam_endpoints: need poses (N, 3) and scans (N, B), got {poses.shape}, {scans.shape}")
    b = scans.shape[1]
    ang = poses[:, 2:3] + 2 * np.pi * np.arange(b) / b
    pts = poses[:, None, :2] + scans[..., None] * np.stack([np.cos(ang), np.sin(ang)], -1)
    return pts[scans < hit_fraction * lidar_range]


def obstacle_penalty_grid(endpoints, n_readings: int, extent: float, side: int, floor: float = 1e-4) -> np.ndarray:
    """``L_obstacle`` on a ``side x side`` grid over ``[0, extent]^2``: the histogram of ``endpoints``
    divided by ``n_readings = N K_laser`` (Appendix E), as ``log(p + floor) - log(floor)`` (0 where no
    beam ended, growing with the density of end points)."""
    if side < 2 or extent <= 0 or n_readings < 1:
        raise ValueError(f"obstacle_penalty_grid: need side >= 2, extent > 0, n_readings >= 1; "
                         f"got {side}, {extent}, {n_readings}")
    e = np.asarray(endpoints, float).reshape(-1, 2)
    counts, _, _ = np.histogram2d(e[:, 0], e[:, 1], bins=side, range=[[0, extent], [0, extent]])
    return np.log(counts / n_readings + floor) - np.log(floor)


def penalty_at(grid, points, extent: float):
    """Bilinear interpolation of the penalty ``grid (side, side)`` at points ``(..., 2)`` (cell centres
    as in :mod:`cogmap.genmodel.charts`)."""
    return bilinear_read(jnp.asarray(grid)[..., None], points, extent)[..., 0]


# -- controls and rollouts -----------------------------------------------------------------------

def squash_controls(raw, max_turn: float, max_step: float, steer_only: bool = False):
    """Raw ``(..., T, 2)`` to controls ``(d_phi, d_p)``: the first turn in ``[-pi, pi]``, later ones in
    ``[-max_turn, max_turn]`` (tanh), forward steps in ``[0, max_step]`` (sigmoid), or all ``max_step``
    with ``steer_only``."""
    bound = jnp.full(raw.shape[-2], max_turn).at[0].set(jnp.pi)
    fwd = jnp.full_like(raw[..., 1], max_step) if steer_only else max_step * jax.nn.sigmoid(raw[..., 1])
    return jnp.stack([bound * jnp.tanh(raw[..., 0]), fwd], -1)


def rollout(start, controls, noise=None, sigma_t=None):
    """Poses ``(T + 1, 3)`` from ``start (3,)`` under ``controls (T, 2)`` through the engineered
    transition; with ``noise (T, 3)`` standard normals and ``sigma_t (3,)`` a reparameterised sample."""

    def body(z, inp):
        u, e = inp
        z = kinematic_mean(z, u)
        if sigma_t is not None:
            z = z + jnp.asarray(sigma_t) * e
            z = z.at[2].set(wrap_angle(z[2]))
        return z, z

    eps = jnp.zeros((controls.shape[0], 3)) if noise is None else noise
    _, zs = jax.lax.scan(body, jnp.asarray(start, float), (controls, eps))
    return jnp.concatenate([jnp.asarray(start, float)[None], zs])


class Candidates(NamedTuple):
    """Optimised ``controls (F, T, 2)``, the random ``initial`` ones, and their expected obstacle
    penalties ``penalty_initial (F,)`` and ``penalty (F,)``."""

    controls: np.ndarray
    initial: np.ndarray
    penalty_initial: np.ndarray
    penalty: np.ndarray


def candidate_controls(key, starts, grid, extent: float, cfg: MIConfig, sigma_t=(0.0, 0.0, 0.0)):
    """``F`` control sequences minimising the expected obstacle penalty (Eq. 8) from random initial
    sequences (Algorithm 2): a :class:`Candidates` with the optimised and the initial controls
    ``(F, T, 2)`` and their expected penalties ``(F,)``.

    ``starts (P, 3)``: current pose particles; each rollout starts from one of them and adds transition
    noise (fixed draws, so the objective is smooth in the controls)."""
    starts = jnp.atleast_2d(jnp.asarray(starts, float))
    F, T, S = cfg.n_candidates, cfg.horizon, cfg.pose_samples
    k_turn, k_step, k_start, k_noise = jax.random.split(key, 4)
    turns = 0.4 * jax.random.normal(k_turn, (F, T))
    first = jax.random.uniform(jax.random.fold_in(k_turn, 1), (F,), minval=-0.98, maxval=0.98)
    turns = turns.at[:, 0].set(jnp.arctanh(first))  # the first turn: any direction
    raw = jnp.stack([turns, cfg.init_forward + 0.5 * jax.random.normal(k_step, (F, T))], -1)
    z0 = starts[jax.random.randint(k_start, (F, S), 0, starts.shape[0])]
    eps = jax.random.normal(k_noise, (F, S, T, 3))
    opt, before, after = _optimise(raw, z0, eps, jnp.asarray(grid, float), jnp.asarray(sigma_t, float), float(extent),
                                   cfg)
    return Candidates(np.asarray(squash_controls(opt, cfg.max_turn, cfg.max_step, cfg.steer_only)),
                      np.asarray(squash_controls(raw, cfg.max_turn, cfg.max_step, cfg.steer_only)), np.asarray(before),
                      np.asarray(after))


def _penalty_loss(raw, z0, eps, grid, sig, extent, cfg):
    """Summed objective of Eq. 8 plus the turn regulariser, and each candidate's expected penalty."""

    def one(r, z0s, e):
        u = squash_controls(r, cfg.max_turn, cfg.max_step, cfg.steer_only)
        zs = jax.vmap(lambda z, n: rollout(z, u, n, sig))(z0s, e)
        pen = jnp.mean(jnp.sum(penalty_at(grid, zs[:, 1:, :2], extent), -1))
        return pen, pen + cfg.turn_reg * jnp.sum(u[1:, 0] ** 2)

    pen, total = jax.vmap(one)(raw, z0, eps)
    return jnp.sum(total), pen


def _optimise_impl(raw, z0, eps, grid, sig, extent, cfg):
    import optax

    opt = optax.adam(cfg.opt_lr)

    def body(carry, _):
        r, s = carry
        g, _ = jax.grad(_penalty_loss, has_aux=True)(r, z0, eps, grid, sig, extent, cfg)
        upd, s = opt.update(g, s, r)
        return (optax.apply_updates(r, upd), s), None

    before = _penalty_loss(raw, z0, eps, grid, sig, extent, cfg)[1]
    (r, _), _ = jax.lax.scan(body, (raw, opt.init(raw)), None, length=cfg.opt_iters)
    return r, before, _penalty_loss(r, z0, eps, grid, sig, extent, cfg)[1]


@jax.jit
def _mean_paths(controls, start):
    return jax.vmap(lambda c: rollout(start, c))(controls)


def mean_paths(controls, start) -> np.ndarray:
    """Mean poses ``(F, T + 1, 3)`` of candidates ``(F, T, 2)`` rolled out from ``start (3,)`` (compiled once
    per shape, not at every call)."""
    return np.asarray(_mean_paths(jnp.asarray(controls, float), jnp.asarray(start, float)))


def cut_forward(controls, free) -> np.ndarray:
    """A copy of ``controls (F, T, 2)`` whose forward steps are 0 from step ``free[f]`` of candidate ``f`` on
    (the agent stands and only turns)."""
    u = np.array(controls, float)
    u[np.arange(u.shape[1])[None, :] >= np.asarray(free)[:, None], 1] = 0.0
    return u


def penalty_free_steps(paths, grid, extent: float, level: float = 0.5) -> np.ndarray:
    """Steps ``(F,)`` before each mean path ``(F, T + 1, 3)`` (its first pose the start) reads an obstacle
    penalty more than ``level`` above the penalty at its start; ``T`` where it never does."""
    grid = jnp.asarray(grid, float)
    pen0 = np.asarray(penalty_at(grid, jnp.asarray(paths[:, :1, :2]), extent))  # (F, 1)
    hit = np.asarray(penalty_at(grid, jnp.asarray(paths[:, 1:, :2]), extent)) > pen0 + level
    return np.where(hit.any(1), hit.argmax(1), paths.shape[1] - 1)


def truncate_at_collision(controls, start, grid, extent: float, level: float = 0.5):
    """Cut every candidate ``(F, T, 2)`` at its first predicted collision: from the first step whose mean
    pose (rolled out from ``start (3,)``) reads an obstacle penalty more than ``level`` above the penalty
    at ``start``, the forward steps are set to 0 (the agent stands and only turns). Returns the cut
    controls and the free steps ``(F,)``.

    Our addition to the paper's procedure: a candidate that runs into a wall is then scored (and executed)
    only up to the wall, so it gains no information from views it would never reach. The threshold is
    relative to the start because the agent stands where it stands: in a corridor narrower than a few
    histogram cells, or beside a wall, the penalty at the start is already above ``level``, and an
    absolute threshold would cut every candidate at its first step and leave the agent standing for good."""
    free = penalty_free_steps(mean_paths(controls, start), grid, extent, level)
    return cut_forward(controls, free), free


def scan_free_steps(paths, scan, lidar_range: float, margin: float, hit_fraction: float = 0.97) -> np.ndarray:
    """Steps ``(F,)`` each mean path ``(F, T + 1, 3)`` (its first pose the current pose) stays inside the
    free region the current ``scan (B,)`` shows: a path point at bearing ``b`` and distance ``d`` from the
    pose counts as blocked when one of the two beams around ``b`` returned from a wall (range below
    ``hit_fraction * lidar_range``) closer than ``d + margin``. Beams that returned nothing bound nothing.

    Our addition: right after a bump the agent stands at a wall, where the obstacle penalty already peaks
    and :func:`truncate_at_collision` (a rise above the start) cannot see it; the scan still can."""
    scan = np.asarray(scan, float)
    n = scan.size
    pose = paths[0, 0]
    rel = paths[:, 1:, :2] - pose[:2]
    d = np.hypot(rel[..., 0], rel[..., 1])
    beam = (np.arctan2(rel[..., 1], rel[..., 0]) - pose[2]) % (2 * np.pi) / (2 * np.pi / n)
    lo = np.floor(beam).astype(int) % n
    wall = np.where(scan < hit_fraction * lidar_range, scan, np.inf)
    bound = np.minimum(wall[lo], wall[(lo + 1) % n])
    hit = (d + margin > bound) & (d > 1e-9)
    return np.where(hit.any(1), hit.argmax(1), paths.shape[1] - 1)


# -- mutual information (Section VI-B) -----------------------------------------------------------

def predictive_samples(key, q_map, emission, model: DVBFConfig, starts, controls, cfg: MIConfig):
    """Ancestral samples of the scans along one control sequence ``controls (T, 2)`` (jitted).

    Returns numpy ``marginal (L, D)`` (each with its own map sample ``M ~ q(M)``) and ``conditionals
    (M, K, D)`` (``K`` per map sample), ``D = n_obs * n_beams`` for the scans at every ``obs_every``-th
    step. Each sample starts from a random particle of ``starts (P, 3)`` and draws its own transition
    and emission noise."""
    marg, cond = _predictive_samples(key, q_map, emission, model, jnp.atleast_2d(jnp.asarray(starts, float)),
                                     jnp.asarray(controls, float), cfg)
    return np.asarray(marg), np.asarray(cond)


def _predictive(key, q_map, emission, model, starts, controls, cfg):
    from cogmap.genmodel.latent_map import sample_map

    T = controls.shape[0]
    obs_idx = jnp.arange(cfg.obs_every, T + 1, cfg.obs_every) if T >= cfg.obs_every else jnp.array([T])
    sig = jnp.asarray(model.sigma_t, float)

    def scans_of(k, grid, n):
        k_s, k_n, k_e = jax.random.split(k, 3)
        z0 = starts[jax.random.randint(k_s, (n,), 0, starts.shape[0])]
        zs = jax.vmap(lambda z, e: rollout(z, controls, e, sig))(z0, jax.random.normal(k_n, (n, T, 3)))
        zo = zs[:, obs_idx]  # (n, n_obs, 3)
        mu = jax.vmap(jax.vmap(lambda z: predict_scan(emission, grid, z, model)))(zo)
        x = mu + model.sigma_e * jax.random.normal(k_e, mu.shape)
        return x.reshape(n, -1)

    k_m, k_c, k_cm = jax.random.split(key, 3)
    marginal = jax.vmap(lambda k: scans_of(k, sample_map(jax.random.fold_in(k, 1), q_map), 1)[0])(
        jax.random.split(k_m, cfg.n_marginal))
    conditionals = jax.vmap(lambda km, kc: scans_of(kc, sample_map(km, q_map), cfg.n_per_map))(
        jax.random.split(k_cm, cfg.n_maps), jax.random.split(k_c, cfg.n_maps))
    return marginal, conditionals


def _jit(f):
    import equinox as eqx

    return eqx.filter_jit(f)


_predictive_samples = _jit(_predictive)


def projected_mutual_information(marginal, conditionals, dim: int = 4) -> float:
    """``H(X) - mean_m H(X | M_m)`` (Eq. 6) after projecting every sample onto the ``dim`` leading
    principal directions of all samples together (a lower bound of the unprojected MI, see module)."""
    marg = np.asarray(marginal, float)
    cond = np.asarray(conditionals, float)
    if marg.ndim != 2 or cond.ndim != 3 or cond.shape[2] != marg.shape[1]:
        raise ValueError(f"projected_mutual_information: need marginal (L, D), conditionals (M, K, D); "
                         f"got {marg.shape}, {cond.shape}")
    pooled = np.concatenate([marg, cond.reshape(-1, cond.shape[2])])
    centre = pooled.mean(0)
    d = min(dim, marg.shape[1])
    _, _, vt = np.linalg.svd(pooled - centre, full_matrices=False)
    basis = vt[:d].T
    return mutual_information((marg - centre) @ basis, (cond - centre) @ basis)


def score_candidates(key, q_map, emission, model: DVBFConfig, starts, candidates, cfg: MIConfig) -> np.ndarray:
    """MI estimate ``(F,)`` of each candidate control sequence ``(F, T, 2)`` (Eq. 6)."""
    keys = jax.random.split(key, len(candidates))
    return np.array([projected_mutual_information(*predictive_samples(k, q_map, emission, model, starts, u, cfg),
                                                  dim=cfg.dim) for k, u in zip(keys, candidates, strict=True)])


_optimise = _jit(_optimise_impl)

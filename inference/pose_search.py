"""The pose of one observation in a learned DVBF-LM: the mode of ``p(z | x, q(M))`` (paper Section V-B c).

Pose-to-observation navigation needs the pose a goal observation was taken at. The paper trains a
pose encoder on the learned map; here the encoder is a search of the same posterior, with a uniform
prior over poses and the Gaussian emission at the map mean, ``log p(x | z) = -|x - mu(z)|^2 / (2
sigma^2) + const``:

1. :func:`build_table` predicts the scans of a grid of poses once per model (``n_xy x n_xy``
   positions times ``n_heading`` headings);
2. :func:`table_log_likelihood` scores an observation against every entry (a matrix product);
3. :func:`refine` moves the ``top`` best entries by Adam on ``-log p(x | z)`` through the emission
   and the chart (jax gradients), and :func:`encode` returns the best refined pose.

An observation seen at several places of a maze (aliasing) can land on the wrong one: the search
returns the likelihood's mode, which is then the wrong place. Pure functions; jax only in
:func:`refine`.
"""

from __future__ import annotations

import functools
from typing import NamedTuple

import numpy as np


class PoseTable(NamedTuple):
    """Poses ``(N, 3)`` and the model's predicted scans ``(N, n_beams)`` there."""

    poses: np.ndarray
    scans: np.ndarray


def pose_grid(extent: float, n_xy: int, n_heading: int) -> np.ndarray:
    """Poses on a regular grid: cell centres of an ``n_xy x n_xy`` grid over ``[0, extent]^2``, each with
    ``n_heading`` headings ``2 pi k / n_heading - pi``.

    Parameters
    ----------
    extent : float
        Side of the world.
    n_xy, n_heading : int
        Positions per side and headings per position.

    Returns
    -------
    numpy.ndarray, shape (n_xy * n_xy * n_heading, 3)

    Raises
    ------
    ValueError
        For sizes below 1 or a non-positive extent.
    """
    if n_xy < 1 or n_heading < 1 or extent <= 0:
        raise ValueError(f"pose_grid: need n_xy, n_heading >= 1 and extent > 0, got {n_xy}, {n_heading}, {extent}")
    c = (np.arange(n_xy) + 0.5) / n_xy * extent
    h = 2 * np.pi * np.arange(n_heading) / n_heading - np.pi
    x, y, t = np.meshgrid(c, c, h, indexing="ij")
    return np.stack([x.ravel(), y.ravel(), t.ravel()], 1)


def build_table(scan_fn, extent: float, n_xy: int = 50, n_heading: int = 20, chunk: int = 4096) -> PoseTable:
    """Predicted scans of :func:`pose_grid` poses.

    Parameters
    ----------
    scan_fn : callable
        ``scan(poses (K, 3)) -> ranges (K, n_beams)``, e.g. the learned model's prediction at the map mean.
    extent : float
        Side of the world.
    n_xy, n_heading : int
        Grid sizes.
    chunk : int
        Poses per call of ``scan_fn``.

    Returns
    -------
    PoseTable
    """
    poses = pose_grid(extent, n_xy, n_heading)
    scans = np.concatenate([np.asarray(scan_fn(poses[a:a + chunk]), float) for a in range(0, len(poses), chunk)])
    return PoseTable(poses, scans)


def table_log_likelihood(obs, table: PoseTable, sigma: float) -> np.ndarray:
    """``log p(x | z_k)`` of observation ``obs (n_beams,)`` for every table pose, up to a constant.

    Parameters
    ----------
    obs : array_like, shape (n_beams,)
        The observed ranges.
    table : PoseTable
        Poses and predicted scans.
    sigma : float
        Emission std per beam.

    Returns
    -------
    numpy.ndarray, shape (N,)
        ``-|obs - scan_k|^2 / (2 sigma^2)``.

    Raises
    ------
    ValueError
        If ``obs`` does not have the table's number of beams, or ``sigma <= 0``.
    """
    obs = np.asarray(obs, float).ravel()
    if obs.size != table.scans.shape[1] or sigma <= 0:
        raise ValueError(f"table_log_likelihood: need {table.scans.shape[1]} beams and sigma > 0, got "
                         f"{obs.size}, {sigma}")
    d2 = np.sum(table.scans**2, 1) - 2 * table.scans @ obs + obs @ obs
    return -0.5 * np.maximum(d2, 0.0) / sigma**2


@functools.lru_cache(maxsize=8)
def _refiner(cfg, iters: int, lr: float):
    import equinox as eqx
    import jax
    import jax.numpy as jnp
    import optax

    from cogmap.genmodel.dvbf import predict_scan
    from cogmap.genmodel.numerics import wrap_angle

    opt = optax.adam(lr)

    @eqx.filter_jit
    def run(emission, grid, obs, starts, sigma):
        def nll(z):
            r = (predict_scan(emission, grid, z, cfg) - obs) / sigma
            return 0.5 * jnp.sum(r * r)

        def one(z0):
            def body(carry, _):
                z, s = carry
                g = jax.grad(nll)(z)
                upd, s = opt.update(g, s, z)
                z = optax.apply_updates(z, upd)
                z = jnp.stack([jnp.clip(z[0], 0.0, cfg.extent), jnp.clip(z[1], 0.0, cfg.extent), wrap_angle(z[2])])
                return (z, s), None

            (z, _), _ = jax.lax.scan(body, (z0, opt.init(z0)), None, length=iters)
            return z, -nll(z)

        return jax.vmap(one)(starts)

    return run


def refine(emission, grid, cfg, obs, starts, sigma: float, iters: int = 100, lr: float = 0.003):
    """Adam on ``-log p(x | z)`` from each start pose, through the emission at the map ``grid``.

    Parameters
    ----------
    emission
        The emission network.
    grid : jax.Array, shape (w, h, D)
        The map (e.g. the mean of q(M)).
    cfg : DVBFConfig
        The model.
    obs : array_like, shape (n_beams,)
        The observation.
    starts : array_like, shape (k, 3)
        Start poses.
    sigma : float
        Emission std per beam.
    iters : int
        Adam steps.
    lr : float
        Adam learning rate (world units and radians per step at most, roughly).

    Returns
    -------
    poses : numpy.ndarray, shape (k, 3)
        Refined poses, positions kept in ``[0, extent]``, headings wrapped.
    log_lik : numpy.ndarray, shape (k,)
        ``-|obs - mu(z)|^2 / (2 sigma^2)`` there.
    """
    import jax.numpy as jnp

    z, ll = _refiner(cfg, int(iters), float(lr))(emission, grid, jnp.asarray(obs, jnp.float32),
                                                 jnp.asarray(starts, jnp.float32), float(sigma))
    return np.asarray(z, float), np.asarray(ll, float)


def encode(obs, table: PoseTable, sigma: float, refine_fn=None, top: int = 8):
    """The most likely pose of ``obs``: the ``top`` best table entries, refined by ``refine_fn``.

    Parameters
    ----------
    obs : array_like, shape (n_beams,)
        The observation.
    table : PoseTable
        From :func:`build_table`.
    sigma : float
        Emission std per beam.
    refine_fn : callable, optional
        ``refine_fn(obs, starts (top, 3)) -> (poses (top, 3), log_lik (top,))``, e.g. :func:`refine`
        with the model bound; None keeps the table poses.
    top : int
        Entries refined.

    Returns
    -------
    pose : numpy.ndarray, shape (3,)
        The best pose.
    log_lik : float
        Its log-likelihood (up to the constant of :func:`table_log_likelihood`).
    """
    ll = table_log_likelihood(obs, table, sigma)
    best = np.argsort(-ll)[:max(1, int(top))]
    poses, scores = table.poses[best], ll[best]
    if refine_fn is not None:
        poses, scores = refine_fn(obs, poses)
    i = int(np.argmax(scores))
    return np.asarray(poses[i], float), float(scores[i])

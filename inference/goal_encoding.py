"""Pose-to-observation goals (paper Section V-B): the pose of a goal's scan, found by the pose search
of :mod:`cogmap.inference.pose_search` on the learned model."""

from __future__ import annotations

import time

import numpy as np

from cogmap.genmodel.dvbf_scan import learned_scan_fn

#: the pose search of pose-to-observation (:mod:`cogmap.inference.pose_search`): a table of n_xy x n_xy
#: positions x n_heading headings scored at once, the best ``top`` refined by ``iters`` Adam steps
ENCODER = {"n_xy": 50, "n_heading": 40, "top": 8, "iters": 100, "lr": 0.003}


def goal_table(params, cfg, encoder: dict = ENCODER):
    """The learned model's predicted scans on the pose grid of ``encoder`` (map mean), for :func:`encode_goals`.

    Parameters
    ----------
    params, cfg : DVBFParams, DVBFConfig
        The learned model and its configuration (see
        :func:`cogmap.genmodel.dvbf_scan.learned_scan_fn`).
    encoder : dict
        ``n_xy`` and ``n_heading`` (see :data:`ENCODER`).

    Returns
    -------
    PoseTable
    """
    from cogmap.inference.pose_search import build_table

    return build_table(learned_scan_fn(params, cfg, 0.0), cfg.extent, encoder["n_xy"], encoder["n_heading"])


def encode_goals(sim, poses, params, cfg, encoder: dict = ENCODER, table=None) -> dict:
    """Pose-to-observation goals: the pose of each goal's scan (the simulator's LiDAR at ``poses``) by the
    pose search on the learned model, and its position error against the true pose.

    Parameters
    ----------
    sim : MazeSim
        The simulator that takes the goal scans.
    poses : numpy.ndarray, shape (n, 3)
        The true goal poses.
    params, cfg
        The learned model.
    encoder : dict
        Search settings (:data:`ENCODER`).
    table : PoseTable, optional
        A table from :func:`goal_table` (built here if None).

    Returns
    -------
    dict
        ``poses`` (n, 3) found, ``errors`` (list of position errors, maze units), ``seconds`` (search
        wall clock, without building the table).
    """
    from cogmap.inference.pose_search import encode, refine

    table = goal_table(params, cfg, encoder) if table is None else table
    tic = time.perf_counter()
    obs = sim.lidar_batch(poses)

    def refine_fn(o, starts):
        return refine(params.emission, params.q_map.mean, cfg, o, starts, sigma=cfg.sigma_e,
                      iters=encoder["iters"], lr=encoder["lr"])

    found = np.array([encode(o, table, cfg.sigma_e, refine_fn, top=encoder["top"])[0] for o in obs])
    errors = np.hypot(*(found[:, :2] - np.asarray(poses)[:, :2]).T)
    return {"poses": found, "errors": [float(e) for e in errors], "seconds": time.perf_counter() - tic}



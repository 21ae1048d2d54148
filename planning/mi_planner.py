"""The DVBF-LM exploration planner (Algorithms 1-2 of the DVBF-LM paper): candidate control
sequences from the current particles, truncated at their predicted collisions with an obstacle
histogram of the map, scored by the mutual information ``I(x_1:T; M)``
(:mod:`cogmap.planning.mi_exploration`), with an optional pull toward the nearest frontier of the
agent's own sensed grid (:mod:`cogmap.planning.frontier_pull`) when every score is low."""

from __future__ import annotations

import functools

import numpy as np

from .mi_exploration import MIConfig


@functools.lru_cache(maxsize=8)
def _scan_predictor(model):
    """Jitted mean scans ``(N, n_beams)`` at poses ``(N, 3)`` for one map grid (one per model and process)."""
    import equinox as eqx
    import jax

    from cogmap.genmodel.dvbf import predict_scan

    @eqx.filter_jit
    def predicted(emission, grid, poses):
        return jax.vmap(lambda z: predict_scan(emission, grid, z, model))(poses)

    return predicted


class MIPlanner:
    """One planning call of the DVBF-LM agent on the current SLAM state (Algorithms 1-2).

    Parameters
    ----------
    model : DVBFConfig
        The SLAM's model (map extent, LiDAR range, transition noise).
    mi : MIConfig
        Candidate generation and scoring settings (Appendix E).
    extent : float
        Maze side in maze units.
    seed : int
        Seed of the planner's random keys.
    penalty_from : str
        ``"predicted"`` (map-mean scans, Algorithm 2 line 6) or ``"observed"`` scans for the
        obstacle histogram.

    Raises
    ------
    ValueError
        For any other ``penalty_from``.
    """

    def __init__(self, model, mi: MIConfig, extent: float, seed: int, penalty_from: str = "predicted"):
        import jax

        if penalty_from not in ("predicted", "observed"):
            raise ValueError(f"MIPlanner: penalty_from must be 'predicted' or 'observed', got {penalty_from!r}")
        self.penalty_from = penalty_from
        self.model, self.mi, self.extent = model, mi, extent
        self.side = max(2, int(np.ceil(extent / mi.hist_cell)))
        self.key = jax.random.PRNGKey(seed + 91)
        self.n_hist = 400  # visited poses used for the obstacle histogram (fixed: one compilation)
        self._predicted = _scan_predictor(model)
        if mi.pull_below is not None:  # the agent's own sensed grid, for the frontier pull
            n = max(2, int(np.ceil(extent / mi.pull_cell)))
            self.crossed, self.ended, self.swept = np.zeros((n, n), np.int64), np.zeros((n, n), np.int64), 0

    def plan(self, slam, rng: np.random.Generator) -> tuple[np.ndarray, dict]:
        """Best candidate control sequence by the mutual information ``I(x_1:T; M)`` (Section VI).

        The obstacle penalty grid is built from 400 poses drawn among the SLAM's estimates so far (their
        observed scans, or the map mean's scans there with ``"predicted"``); candidates start from the current
        particles and are truncated at their predicted collision (in the penalty and, with
        ``MIConfig.scan_margin``, in the current scan); the ones with the longest free prefix (all of them
        with ``MIConfig.feasible_only`` off) are scored by
        :func:`cogmap.planning.mi_exploration.score_candidates`.

        Parameters
        ----------
        slam : OnlineSLAM
            Current filter and map state (read only; :class:`cogmap.inference.online_slam.OnlineSLAM` or
            anything with its ``t``, ``estimates``, ``estimate``, ``scans``, ``particles`` and ``params``).
        rng : numpy.random.Generator
            Draws the poses of the obstacle histogram.

        Returns
        -------
        controls : numpy.ndarray, shape (horizon, 2)
            The best sequence (turn rad, forward maze units), forward set to 0 from its predicted collision on.
        info : dict
            ``scores``, ``best`` (index), ``penalty``, ``grid`` (obstacle penalty), ``controls`` (all
            candidates), ``free_steps`` (steps before each candidate's predicted collision), ``starts``
            (the particles).
        """
        import jax
        import jax.numpy as jnp

        from cogmap.planning.mi_exploration import (
            beam_endpoints,
            candidate_controls,
            cut_forward,
            mean_paths,
            obstacle_penalty_grid,
            penalty_free_steps,
            scan_free_steps,
            score_candidates,
        )

        t = slam.t
        idx = rng.integers(0, t + 1, self.n_hist)
        poses = slam.estimates[idx]
        q = slam.params.q_map
        if self.penalty_from == "predicted":  # Algorithm 2, l. 6: scans predicted by the map mean
            x_hat = np.asarray(self._predicted(slam.params.emission, q.mean, jnp.asarray(poses)))
        else:  # the scans the agent received there
            x_hat = slam.scans[idx]
        ends = beam_endpoints(poses, x_hat, self.model.lidar_range)
        grid = obstacle_penalty_grid(ends, x_hat.size, self.extent, self.side)
        self.key, k_c, k_s = jax.random.split(self.key, 3)
        starts = slam.particles
        cand = candidate_controls(k_c, starts, grid, self.extent, self.mi, sigma_t=self.model.sigma_t)
        # one rollout of the candidates' mean paths serves both collision checks
        paths = mean_paths(cand.controls, slam.estimate)
        free = penalty_free_steps(paths, grid, self.extent, self.mi.collision_level)
        if self.mi.scan_margin is not None:  # also stop where the current scan shows a wall
            free = np.minimum(free, scan_free_steps(paths, slam.scans[t], self.model.lidar_range,
                                                    self.mi.scan_margin))
        controls = cut_forward(cand.controls, free)
        # the argmax runs over the candidates the obstacle optimisation made safe (no predicted collision, else
        # the longest free prefix): a cut candidate stands at its wall, and standing still scores a high
        # I(x_1:T; M) (repeated scans of one place, no pose diffusion) without exploring anything
        feasible = free == free.max() if self.mi.feasible_only else np.ones(len(free), bool)
        scores = np.full(len(free), -np.inf)
        scores[feasible] = score_candidates(k_s, q, slam.params.emission, self.model, starts, controls[feasible],
                                            self.mi)
        best = int(np.argmax(scores))
        info = {"scores": scores, "best": best, "penalty": cand.penalty, "grid": grid, "controls": controls,
                "free_steps": free, "starts": np.asarray(starts), "pulled": False}
        if self.mi.pull_below is not None:
            self._sweep(slam)
            if scores[best] < self.mi.pull_below:
                self._pull(slam, info)
        return info["controls"][info["best"]], info

    def _sweep(self, slam) -> None:
        """Add the scans received since the last call, at their estimated poses, to the sensed grid."""
        from cogmap.planning.frontier_pull import sweep

        t = slam.t + 1
        sweep(self.crossed, self.ended, slam.estimates[self.swept:t], slam.scans[self.swept:t],
              self.model.lidar_range, self.extent)
        self.swept = t

    def _pull(self, slam, info: dict) -> None:
        """Replace the plan by the way to the nearest frontier of the sensed grid when one is reachable,
        cut where the mean path of its controls would enter a wall cell of that grid or a neighbour of
        one, if that leaves at least ``MIConfig.obs_every`` steps. The candidates' collision checks are
        not applied: the obstacle histogram's cells are twice as coarse as the sensed grid the way was
        planned on, and the scan check (two beams 18 degrees apart bound each bearing) closes doorways;
        in corridors a few cells wide either cut the way at its first bend. A bump still re-plans."""
        from cogmap.planning.frontier_pull import blocked, descend, free_steps, frontier_distance, pursue
        from cogmap.planning.mi_exploration import cut_forward, mean_paths

        mi = self.mi
        dist, cost = frontier_distance(self.crossed, self.ended, mi.pull_hit_min, mi.pull_min_crossed)
        path = descend(dist, cost, slam.estimate[:2], self.extent)
        info["pull_path"] = path
        if len(path) < 2:
            return
        u = pursue(path, slam.estimate, mi.horizon, mi.max_turn, mi.max_step)[None]
        walls = blocked(self.crossed, self.ended, mi.pull_hit_min)
        free = np.array([free_steps(mean_paths(u, slam.estimate)[0, :, :2], walls, self.extent)])
        if int(free[0]) < mi.obs_every:
            return
        info["controls"] = np.concatenate([info["controls"], cut_forward(u, free)])
        info["free_steps"] = np.concatenate([info["free_steps"], free])
        info["scores"] = np.append(info["scores"], np.nan)
        info["best"], info["pulled"] = len(info["free_steps"]) - 1, True

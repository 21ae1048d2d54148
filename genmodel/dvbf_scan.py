"""The learned DVBF-LM as a scan function: predicted LiDAR ranges at poses from the emission on the
chart of q(M), for planning in the learned model (paper Section V)."""

from __future__ import annotations

import numpy as np

STD_K = 1.0  # planning ranges: predicted mean minus this many standard deviations under q(M)


def learned_scan_fn(params, cfg, k_std: float = STD_K):
    """``scan_fn`` of the learned model: ranges at poses ``(K, 3)`` from the emission on the chart of
    q(M), lowered by ``k_std`` standard deviations of the prediction under the map's uncertainty (first
    order, :meth:`~cogmap.genmodel.dvbf.Emission.mean_and_variance`). ``k_std = 0`` is the prediction at
    the map mean alone. With ``k_std > 0`` parts of the map the traversal never saw (q(M) still at the
    prior) read as close, so the safety term keeps plans out of them; at the mean they can read as open
    (maze 2: 4 of 30 plans at the mean crossed an unseen wall, none with ``k_std = 1``).
    Batches are padded to powers of two so few shapes are ever compiled.

    Parameters
    ----------
    params : DVBFParams
        The learned q(M) and emission network.
    cfg : DVBFConfig
        Their model (extent, beams, chart radii).
    k_std : float
        Standard deviations subtracted from the predicted ranges (default :data:`STD_K`).

    Returns
    -------
    callable
        ``scan(poses)``: poses ``(K, 3)`` (or one ``(3,)``) to ranges ``numpy.ndarray (K, n_beams)``
        in maze units.
    """
    import equinox as eqx
    import jax
    import jax.numpy as jnp

    from cogmap.genmodel.charts import chart

    radii = jnp.asarray(cfg.radii)
    mean_grid = params.q_map.mean
    var_grid = jnp.exp(2.0 * params.q_map.log_std)
    k = float(k_std)

    @eqx.filter_jit
    def batch(emission, mean_grid, var_grid, poses):
        def one(z):
            m = chart(mean_grid, z, cfg.extent, cfg.n_beams, radii)
            if k == 0.0:
                return emission(m)
            mu, var = emission.mean_and_variance(m, chart(var_grid, z, cfg.extent, cfg.n_beams, radii, power=2))
            return mu - k * jnp.sqrt(var)

        return jax.vmap(one)(poses)

    def scan(poses):
        poses = np.asarray(poses, np.float32).reshape(-1, 3)
        n = len(poses)
        size = 1 << max(4, (n - 1).bit_length())
        pad = np.zeros((size, 3), np.float32)
        pad[:n] = poses
        return np.asarray(batch(params.emission, mean_grid, var_grid, jnp.asarray(pad)))[:n].astype(float)

    return scan



def scan_models(params, cfg, sim, k_std: float = STD_K) -> dict:
    """The three worlds each pair is planned in: ``learned`` (q(M), ranges lowered by ``k_std``
    standard deviations), ``learned_mean`` (the prediction at the map mean, the paper's reading) and
    ``true`` (the simulator's ray casts, the reference row).

    Parameters
    ----------
    params, cfg : DVBFParams, DVBFConfig
        The learned model and its configuration, as :func:`learned_scan_fn` takes them.
    sim : MazeSim
        The true simulator (its ``lidar_batch``).
    k_std : float
        Standard deviations for ``learned`` (default :data:`STD_K`).

    Returns
    -------
    dict of str to callable
        ``{"learned", "learned_mean", "true"}`` -> ``scan(poses (K, 3)) -> ranges (K, n_beams)``.
    """
    return {"learned": learned_scan_fn(params, cfg, k_std), "learned_mean": learned_scan_fn(params, cfg, 0.0),
            "true": sim.lidar_batch}



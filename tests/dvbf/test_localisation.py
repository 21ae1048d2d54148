"""Seeded behaviour: in a map learnt from one traversal, the particle filter localises a second,
noisier traversal better than path integration."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from cogmap.envs.maze import make_maze
from cogmap.envs.maze_sim import ActuationNoise
from cogmap.envs.maze_traversal import traverse
from cogmap.genmodel.dvbf import DVBFConfig, log_likelihood_marginal, transition_sample
from cogmap.inference.elbo import Batch, init_opt_state, init_params, make_optimizer, make_train_step
from cogmap.inference.online_slam import path_integration
from cogmap.inference.particle_filter import pf_init, pf_run


def test_filter_in_learnt_map_beats_path_integration():
    maze = make_maze(5, "simple", "medium")  # 0.5 x 0.5, 12 x 12 map
    mapping = traverse(maze, 600, seed=0, step=0.006)
    cfg = DVBFConfig(extent=maze.size, map_side=maze.map_side, hidden=32, sigma_t=(0.001, 0.001, 0.02))
    params = init_params(cfg, jax.random.PRNGKey(0))
    opt = make_optimizer(1e-2)
    state = init_opt_state(opt, params)
    step = make_train_step(cfg, opt, len(mapping))
    parts, scans = jnp.asarray(mapping.poses[:, None, :]), jnp.asarray(mapping.scans)
    rng = np.random.default_rng(0)
    for it in range(150):
        idx = rng.integers(0, len(mapping), 32)
        params, state, _ = step(params, state, jax.random.PRNGKey(it), Batch(parts[idx], scans[idx]))

    test = traverse(maze, 400, seed=1, step=0.006, noise=ActuationNoise(rot_std=0.02, trans_frac=0.1))

    @eqx.filter_jit
    def localise(params):
        s0 = pf_init(jnp.tile(jnp.asarray(test.poses[0]), (20, 1)))
        _, (mean, _, _) = pf_run(jax.random.PRNGKey(1), s0, jnp.asarray(test.controls), jnp.asarray(test.scans[1:]),
                                 lambda k, z, u: transition_sample(k, z, u, jnp.asarray(cfg.sigma_t)),
                                 lambda z, x: log_likelihood_marginal(params.emission, params.q_map, z, x, cfg))
        return mean

    mean = np.asarray(localise(params))
    err = np.hypot(*(mean[:, :2] - test.poses[1:, :2]).T)
    pi = path_integration(test.poses[0], test.controls)
    err_pi = np.hypot(*(pi[1:, :2] - test.poses[1:, :2]).T)
    assert err_pi[-1] > 0.03  # the noisy controls drift
    assert err[-1] < 0.5 * err_pi[-1]
    assert err.mean() < 0.5 * err_pi.mean()

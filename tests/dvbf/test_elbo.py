"""ELBO / SVI training on a small maze: the jitted Adam step improves the ELBO and the scans."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from cogmap.envs.maze import make_maze
from cogmap.envs.maze_traversal import traverse
from cogmap.genmodel.dvbf import DVBFConfig, predict_scan
from cogmap.inference.elbo import Batch, init_opt_state, init_params, make_optimizer, make_train_step


def test_elbo_improves_on_small_maze():
    maze = make_maze(0, "simple", "small")  # 0.25 x 0.25, 7 x 7 map (Table II)
    tr = traverse(maze, 300, seed=0, step=0.004)
    cfg = DVBFConfig(extent=maze.size, map_side=maze.map_side, hidden=16, depth=1)
    rng = np.random.default_rng(0)
    particles = jnp.asarray(tr.poses[:, None, :] + rng.normal(0, 0.002, (len(tr.poses), 4, 3)))
    scans = jnp.asarray(tr.scans)
    n = len(tr.poses)
    params = init_params(cfg, jax.random.PRNGKey(0))

    @eqx.filter_jit
    def scan_error(emission_and_mean):
        emission, mean = emission_and_mean
        pred = jax.vmap(lambda z: predict_scan(emission, mean, z, cfg))(jnp.asarray(tr.poses))
        return jnp.mean(jnp.abs(pred - scans))

    err_before = float(scan_error((params.emission, params.q_map.mean)))
    opt = make_optimizer(1e-2)
    state = init_opt_state(opt, params)
    step = make_train_step(cfg, opt, n)
    losses = []
    for it in range(40):
        idx = rng.integers(0, n, 32)
        params, state, terms = step(params, state, jax.random.PRNGKey(it), Batch(particles[idx], scans[idx]))
        losses.append(float(terms.loss))
        assert float(terms.kl_map) >= 0
    err_after = float(scan_error((params.emission, params.q_map.mean)))
    first, last = np.mean(losses[:5]), np.mean(losses[-5:])
    assert np.all(np.isfinite(losses))
    assert last < first - 0.25 * abs(first)  # the negative ELBO (Eq. 3) falls
    assert err_after < 0.7 * err_before

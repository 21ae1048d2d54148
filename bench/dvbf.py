"""DVBF-LM speed: particle-filter steps per second and ELBO (Adam) iterations per second, jitted.

The first call (tracing and XLA compilation) is timed and printed separately from the steady state.

    python bench/dvbf.py [--particles 20 1000] [--batch 32] [--cache 8] [--steps 200] [--iters 100]
"""

from __future__ import annotations

import argparse
import time

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from cogmap.envs.maze import make_maze
from cogmap.envs.maze_traversal import traverse
from cogmap.genmodel.dvbf import DVBFConfig, log_likelihood, transition_sample
from cogmap.inference.elbo import Batch, init_opt_state, init_params, make_optimizer, make_train_step
from cogmap.inference.particle_filter import pf_init, pf_step


def _timed(fn, n):
    t0 = time.perf_counter()
    out = jax.block_until_ready(fn(0))
    first = time.perf_counter() - t0
    t0 = time.perf_counter()
    for i in range(1, n + 1):
        out = fn(i)
    jax.block_until_ready(out)
    return first, n / (time.perf_counter() - t0)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--particles", type=int, nargs="+", default=[20, 1000])
    ap.add_argument("--batch", type=int, default=32, help="time steps per ELBO mini-batch")
    ap.add_argument("--cache", type=int, default=8, help="cached particles per time step in the ELBO")
    ap.add_argument("--steps", type=int, default=200, help="timed filter steps")
    ap.add_argument("--iters", type=int, default=50, help="timed ELBO iterations")
    ap.add_argument("--hidden", type=int, default=32)
    args = ap.parse_args(argv)

    maze = make_maze(0)
    tr = traverse(maze, max(args.steps + 1, args.batch), seed=0)
    cfg = DVBFConfig(extent=maze.size, map_side=maze.map_side, hidden=args.hidden)
    params = init_params(cfg, jax.random.PRNGKey(0))
    scans, controls = jnp.asarray(tr.scans), jnp.asarray(tr.controls)
    sigma_t = jnp.asarray(cfg.sigma_t)
    print(f"maze {maze.size:g} x {maze.size:g}, map {cfg.map_side}x{cfg.map_side}x{cfg.map_dim}, "
          f"{cfg.n_beams} beams x {cfg.n_radii} query points, emission MLP {cfg.depth} x {cfg.hidden}")
    print(f"{'what':<34}{'first call (s)':>16}{'per second':>14}")

    @eqx.filter_jit
    def step(key, state, u, x, emission, grid):
        return pf_step(key, state, u, x, lambda k, z, c: transition_sample(k, z, c, sigma_t),
                       lambda z, o: log_likelihood(emission, grid, z, o, cfg, sigma=0.05))[0]

    for k in args.particles:
        state = pf_init(jnp.tile(jnp.asarray(tr.poses[0]), (k, 1)))
        holder = {"s": state}

        def run(i, holder=holder):
            holder["s"] = step(jax.random.PRNGKey(i), holder["s"], controls[i % len(controls)],
                               scans[1 + i % len(controls)], params.emission, params.q_map.mean)
            return holder["s"].particles

        first, rate = _timed(run, args.steps)
        print(f"{f'particle filter step, K = {k}':<34}{first:>16.2f}{rate:>14.1f}")

    opt = make_optimizer(1e-3)
    holder = {"p": params, "o": init_opt_state(opt, params)}
    train = make_train_step(cfg, opt, len(tr.poses))
    rng = np.random.default_rng(0)
    parts = jnp.asarray(np.repeat(tr.poses[:, None, :], args.cache, 1))

    def it(i):
        idx = rng.integers(0, len(tr.poses), args.batch)
        holder["p"], holder["o"], terms = train(holder["p"], holder["o"], jax.random.PRNGKey(i),
                                                Batch(parts[idx], scans[idx]))
        return terms.loss

    first, rate = _timed(it, args.iters)
    print(f"{f'ELBO Adam step, {args.batch} x {args.cache} particles':<34}{first:>16.2f}{rate:>14.1f}")


if __name__ == "__main__":
    main()

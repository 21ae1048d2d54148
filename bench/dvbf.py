"""DVBF-LM speed: particle-filter steps per second and ELBO (Adam) iterations per second, jitted; the pose
search of pose-to-observation (table of predicted scans, then scans encoded per second) and the frontier
pull's path (distance field and descent on the sensed grid of a 1 x 1 maze, per second).

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

    # pose search (the study's settings: 50 x 50 x 40 table, best 8 refined by 100 Adam steps)
    from cogmap.dvbf.navigate import learned_scan_fn
    from cogmap.inference.pose_search import build_table, encode, refine

    t0 = time.perf_counter()
    table = build_table(learned_scan_fn(params, cfg, 0.0), cfg.extent, 50, 40)
    print(f"{'pose table, 50 x 50 x 40 poses':<34}{time.perf_counter() - t0:>16.2f}{'(once)':>14}")

    def enc(i):
        o = np.asarray(scans[i % len(scans)])
        return jnp.asarray(encode(o, table, 0.03, lambda x, st: refine(params.emission, params.q_map.mean, cfg, x, st,
                                                                          sigma=0.03), top=8)[0])

    first, rate = _timed(enc, 10)
    print(f"{'pose search, one scan (top 8)':<34}{first:>16.2f}{rate:>14.1f}")

    # the frontier pull's way on the sensed grid of the traversal (cells of 0.01)
    from cogmap.planning.frontier_pull import descend, frontier_distance, sweep

    n = int(round(maze.size / 0.01))
    crossed, ended = np.zeros((n, n), np.int64), np.zeros((n, n), np.int64)
    sweep(crossed, ended, tr.poses[:100], tr.scans[:100], cfg.lidar_range, maze.size)

    def pull(i):
        d, c = frontier_distance(crossed, ended)
        return jnp.asarray(descend(d, c, tr.poses[100 + i % 50, :2], maze.size))

    first, rate = _timed(pull, 20)
    print(f"{f'frontier pull path, {n} x {n} grid':<34}{first:>16.2f}{rate:>14.1f}")


if __name__ == "__main__":
    main()

"""Parameter and model recovery on the T-maze: simulate subjects with known parameters, fit, compare.

64 subjects x 100 trials (two choices each) with policy precisions drawn from LogNormal(log 2, 0.5);
MAP estimates of gamma (prior LogNormal(log 2, 0.6)); then model recovery between three candidate
agents (full EFE, utility only, information only), 16 subjects each, by Laplace log evidence.

    python bench/recovery.py [--subjects 64] [--trials 100] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import time

import jax

jax.config.update("jax_enable_x64", True)

import numpy as np  # noqa: E402

from cogmap import fit, jax_agent  # noqa: E402
from cogmap.envs import jax_worlds  # noqa: E402
from cogmap.planning import efe  # noqa: E402


def candidates(free):
    m = jax_worlds.tmaze_model
    return [fit.Candidate("efe", jax_agent.build(m(), policy_len=2, gamma=2.0), free),
            fit.Candidate("utility only", jax_agent.build(m(), policy_len=2, gamma=2.0, objective=efe.objective(
                [(efe.observation_preference, 1.0)])), free),
            fit.Candidate("information only", jax_agent.build(m(), policy_len=2, gamma=2.0, objective=efe.objective(
                [(efe.state_info_gain, 1.0)])), free)]


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--subjects", type=int, default=64)
    ap.add_argument("--trials", type=int, default=100)
    ap.add_argument("--recovery-subjects", type=int, default=16, help="subjects per candidate in model recovery")
    ap.add_argument("--json", metavar="FILE")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    free = (fit.Free("gamma", fit.LogNormal(float(np.log(2.0)), 0.6)),)
    cands = candidates(free)
    world = jax_worlds.tmaze_world()
    true = np.exp(np.random.default_rng(0).normal(np.log(2.0), 0.5, (args.subjects, 1)))
    data = fit.simulate_subjects(cands[0], world, jax.random.key(1), true, trials=args.trials, steps=2)
    res = fit.fit_map(cands[0].agent, free, data, iterations=200)
    est = res.values[:, 0]
    rel = np.abs(est - true[:, 0]) / true[:, 0]
    print(f"gamma: {args.subjects} subjects x {args.trials} trials, median relative error {np.median(rel):.3f}, "
          f"correlation {np.corrcoef(est, true[:, 0])[0, 1]:.3f}")
    n = args.recovery_subjects
    M = fit.confusion(cands, world, jax.random.key(2), lambda i, rng: np.exp(rng.normal(np.log(2.0), 0.5, (n, 1))),
                      subjects=n, trials=args.trials, steps=2, iterations=200)
    print("model recovery (rows: generating, columns: winning):", ", ".join(c.name for c in cands))
    print(np.array2string(M, precision=3))
    print(f"generating agent picked in {np.trace(M) / len(cands):.3f} of simulated subjects")
    seconds = time.perf_counter() - t0
    print(f"{seconds:.1f} s")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"parameter": [{"name": "gamma", "true": true[:, 0].tolist(), "fitted": est.tolist()}],
                       "confusion": M.tolist(), "candidates": [c.name for c in cands], "seconds": seconds}, fh)


if __name__ == "__main__":
    main()

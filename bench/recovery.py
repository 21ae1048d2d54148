"""Parameter and model recovery on the T-maze and the grid task, timed (the recovery study's runs).

64 subjects x 100 trials per task with policy precisions drawn from LogNormal(log 2, 0.5); MAP
estimates of gamma (prior LogNormal(log 2, 0.6)); then model recovery between three candidate
agents (full EFE, utility only, information only) by Laplace log evidence. The same functions
make ``cogmap reproduce recovery`` (``cogmap.study.recovery``).

    python bench/recovery.py [--subjects 64] [--trials 100] [--recovery-subjects 16] [--tasks tmaze grid]
                             [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import time

import jax

jax.config.update("jax_enable_x64", True)

import numpy as np  # noqa: E402

from cogmap.study import recovery  # noqa: E402


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--subjects", type=int, default=64)
    ap.add_argument("--trials", type=int, default=100)
    ap.add_argument("--recovery-subjects", type=int, default=16, help="subjects per candidate in model recovery")
    ap.add_argument("--tasks", nargs="+", default=list(recovery.TASKS), choices=recovery.TASKS)
    ap.add_argument("--json", metavar="FILE")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    out = {"parameter": [], "model": []}
    for task in args.tasks:
        t = time.perf_counter()
        res = recovery.parameter_recovery(task, 0, args.subjects, args.trials, iterations=200)
        print(f"{task}: gamma, {args.subjects} subjects x {args.trials} trials, median relative error "
              f"{res['median_relative_error']:.3f}, correlation {res['correlation']:.3f} "
              f"({time.perf_counter() - t:.1f} s)")
        out["parameter"].append({"name": f"gamma ({task})", "true": res["true"], "fitted": res["fitted"]})
        t = time.perf_counter()
        mod = recovery.model_recovery(task, 0, args.recovery_subjects, args.trials, iterations=200)
        print(f"{task}: model recovery (rows: generating, columns: winning): {', '.join(mod['candidates'])}")
        print(np.array2string(np.asarray(mod["confusion"]), precision=3))
        print(f"{task}: generating agent picked in {mod['recovered']:.3f} of simulated subjects "
              f"({time.perf_counter() - t:.1f} s)")
        out["model"].append({"task": task, **mod})
    out["seconds"] = time.perf_counter() - t0
    print(f"{out['seconds']:.1f} s")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(out, fh)


if __name__ == "__main__":
    main()

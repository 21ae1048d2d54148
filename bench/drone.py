"""Time the drone's planning call and its per-candidate EFE, labelled apart.

"Planning call" = one whole decision as the published planning server answered it (kernel beliefs
re-initialised and updated, candidate generation, per-waypoint suitability, filter, EFE, shaping,
ranking); the paper's "5.43 ms per EFE" is this quantity (median 5.0 ms per step on a 4-core
Windows machine, DRONE.md 2.7). "Per-candidate EFE" = the EFE (preference, EFE, shaping) of one
candidate, in microseconds. Both are collected over seeded flights in the field.

Run: ``python bench/drone.py [--episodes 10] [--seed 0]``.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import platform  # noqa: E402

import numpy as np  # noqa: E402

from cogmap.drone.run import fly_run  # noqa: E402


def cpu_name() -> str:
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--episodes", type=int, default=10)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    res = fly_run(args.seed, args.episodes, None, method="agent")
    calls = np.concatenate([np.asarray(e["plan_ms"], float) for e in res["episodes"]])
    efe = np.array([e["efe_us_per_candidate_median"] for e in res["episodes"]], float)
    print(f"machine: {cpu_name()}, {os.cpu_count()} logical cores, Python {platform.python_version()}")
    print(f"flights: {args.episodes} episodes, field seed {args.seed}, {len(calls)} planning calls")
    print(f"planning call (whole decision): median {np.median(calls):.2f} ms, p5 {np.percentile(calls, 5):.2f} ms, "
          f"p95 {np.percentile(calls, 95):.2f} ms   [paper: median 5.0 ms, p5 4.0, p95 8.6 on 4 cores]")
    print(f"per-candidate EFE: median {np.median(efe):.2f} us (median over episodes of each episode's median)")


if __name__ == "__main__":
    main()

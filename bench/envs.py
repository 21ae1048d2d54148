"""Time one simulator step: move (0.5 m action), 360-ray LiDAR + obstacle signal, 4-view
64x64 panorama. Prints mean and percentiles per part, per layout.

    python bench/envs.py [--steps 200] [--layouts mini_warehouse house ...]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from cogmap.envs.sim import NavSim

PARTS = ("move", "lidar", "panorama", "total")


def bench(layout: str, steps: int, seed: int = 0) -> dict[str, np.ndarray]:
    sim = NavSim(layout, seed=seed)
    rng = np.random.default_rng(seed)
    t = {k: [] for k in PARTS}
    try:
        for _ in range(steps):
            t0 = time.perf_counter()
            sim.step_action(int(rng.integers(13)))
            t1 = time.perf_counter()
            sim.lidar()
            sim.obstacle_signal()
            t2 = time.perf_counter()
            sim.panorama()
            t3 = time.perf_counter()
            for k, v in zip(PARTS, (t1 - t0, t2 - t1, t3 - t2, t3 - t0), strict=True):
                t[k].append(v * 1e3)
    finally:
        sim.close()
    return {k: np.array(v) for k, v in t.items()}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--layouts", nargs="+",
                    default=["mini_warehouse", "house", "large_warehouse", "parking_lot"])
    args = ap.parse_args()
    print(f"{'layout':16s} {'part':9s} {'mean ms':>8s} {'p50':>7s} {'p90':>7s} {'p99':>7s}")
    for lay in args.layouts:
        res = bench(lay, args.steps)
        for k in PARTS:
            v = res[k]
            print(f"{lay:16s} {k:9s} {v.mean():8.2f} {np.percentile(v, 50):7.2f} "
                  f"{np.percentile(v, 90):7.2f} {np.percentile(v, 99):7.2f}")
    print("target: total < 10 ms per step")


if __name__ == "__main__":
    main()

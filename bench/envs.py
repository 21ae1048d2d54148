"""Time one simulator step: move (0.5 m action), 360-ray LiDAR + obstacle signal, 4-view
64x64 panorama. Prints mean and percentiles per part, per layout.

With --ssim, also prints the median SSIM (the agent's place-recognition measure) between
panoramas of places dx apart and of places at least 3 m apart.

    python bench/envs.py [--steps 200] [--layouts mini_warehouse house ...] [--ssim]
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


DXS = (0.1, 0.25, 0.5, 1.0, 2.0)


def ssim_table(layout: str, n: int = 20, seed: int = 1) -> list[float]:
    """Median SSIM per displacement in DXS, then for places >= 3 m apart."""
    from cogmap.agent.encoder import ssim
    from cogmap.envs.places import displaced_pairs, distant_pairs, panorama_at

    sim = NavSim(layout, seed=0, start=0)
    rng = np.random.default_rng(seed)
    try:
        pairs = [displaced_pairs(sim, dx, n, rng) for dx in DXS]
        pairs.append(distant_pairs(sim, 3.0, 2 * n, rng))
        return [float(np.median([ssim(panorama_at(sim, a), panorama_at(sim, b))
                                 for a, b in ps])) for ps in pairs]
    finally:
        sim.close()


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--layouts", nargs="+",
                    default=["mini_warehouse", "house", "large_warehouse", "parking_lot"])
    ap.add_argument("--ssim", action="store_true", help="also print the place SSIM table")
    args = ap.parse_args()
    print(f"{'layout':16s} {'part':9s} {'mean ms':>8s} {'p50':>7s} {'p90':>7s} {'p99':>7s}")
    for lay in args.layouts:
        res = bench(lay, args.steps)
        for k in PARTS:
            v = res[k]
            print(f"{lay:16s} {k:9s} {v.mean():8.2f} {np.percentile(v, 50):7.2f} "
                  f"{np.percentile(v, 90):7.2f} {np.percentile(v, 99):7.2f}")
    print("target: total < 10 ms per step")
    if args.ssim:
        print()
        print(f"{'layout':16s} " + " ".join(f"{f'dx={d:g}':>7s}" for d in DXS) + "   >=3 m")
        for lay in args.layouts:
            row = ssim_table(lay)
            print(f"{lay:16s} " + " ".join(f"{v:7.3f}" for v in row))
        print("targets: >= 0.7 for dx <= 0.25, < 0.6 for dx >= 1, < 0.5 for >= 3 m")


if __name__ == "__main__":
    main()

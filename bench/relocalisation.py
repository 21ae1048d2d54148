"""How recognisable is a revisited place under odometry drift? SSIM of panoramas, with and without
a search over circular column shifts, for pairs of places by true distance.

A robot wanders a pybullet room (random free headings, one step each) with the study's drift
levels (``cogmap.study.config.DRIFT_LEVELS``). Panoramas are rendered from the odometry
heading, so a heading error between two visits rotates one panorama against the other. For
every pair of steps (at least ``--gap`` steps apart) it prints, per bin of true distance,
quantiles (10 / 50 / 90 %) of:

- ``raw``: SSIM of the panoramas as rendered;
- ``search``: the best SSIM over shifts within +-``--max-shift`` columns (``SSIMEncoder.align``);
- ``true-shift``: SSIM after rolling by the true heading difference (what position alone costs);

and, for revisits (< 1 m), how far the shift found lies from the true heading difference.
Then, for pairs whose heading difference lies within the search (the agent corrects its
heading often enough to stay there), the LiDAR scans are aligned (``inference.se2.icp``,
started from the panorama's heading estimate): the fraction of returns within 0.1 m of the
other scan (``icp inliers``) and, for those pairs whose odometry disagrees by at most 1.5 m (what ICP must
bridge after the agent's last correction), the error of the corrected position (m).
The agent's recognition thresholds (``AgentConfig.relocalise_ssim``) are chosen from these numbers.

    python bench/relocalisation.py [--env aisle_warehouse] [--steps 150] [--seed 0]
"""

from __future__ import annotations

import argparse

import numpy as np

from cogmap.agent.encoder import SSIMEncoder, ssim
from cogmap.agent.sensing import scan_points
from cogmap.envs import NavSim, OdometryNoise, SimConfig, make_layout
from cogmap.genmodel.numerics import wrap_angle
from cogmap.inference.se2 import about, apply, icp
from cogmap.study.config import DRIFT_LEVELS

BINS = ((0.0, 0.25), (0.25, 0.5), (0.5, 1.0), (1.0, 2.0), (3.0, np.inf))


def wander(env: str, noise: OdometryNoise, steps: int, step: float, seed: int):
    """Panoramas, true and odometry poses of a random walk over free headings."""
    sim = NavSim(make_layout(env), SimConfig(step_length=step, noise=noise), seed=seed, start=seed % 4)
    rng = np.random.default_rng(seed)
    panos, true, odom, scans = [], [], [], []
    try:
        for _ in range(steps):
            panos.append(sim.panorama())
            true.append(sim.true_pose())
            odom.append(sim.odometry())
            angles = sim.lidar_angles() + odom[-1][2]  # odometry orientation, as the agent senses
            scans.append(scan_points(sim.lidar(), angles, sim.config.lidar_range))
            free = np.flatnonzero(~np.asarray(sim.obstacle_signal(), dtype=bool))
            sim.step_action(int(rng.choice(free)) if free.size else sim.config.n_directions)
    finally:
        sim.close()
    return panos, np.array(true), np.array(odom), scans


def np_rot(a: float) -> np.ndarray:
    return np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])


def pairs(true, gap: int, per_bin: int, rng):
    i, j = np.triu_indices(len(true), k=gap)
    d = np.hypot(*(true[i, :2] - true[j, :2]).T)
    out = {}
    for lo, hi in BINS:
        k = np.flatnonzero((d >= lo) & (d < hi))
        out[(lo, hi)] = (i[k], j[k]) if k.size <= per_bin else tuple(a[rng.choice(k, per_bin, replace=False)]
                                                                        for a in (i, j))
    return out


def q(x) -> str:
    if len(x) == 0:
        return "     -    "
    a, b, c = np.percentile(x, [10, 50, 90])
    return f"{a:.2f}/{b:.2f}/{c:.2f}"


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--env", default="aisle_warehouse")
    p.add_argument("--steps", type=int, default=150)
    p.add_argument("--step", type=float, default=1.0, help="step length (m)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--gap", type=int, default=3, help="pairs at least this many steps apart")
    p.add_argument("--per-bin", type=int, default=120)
    p.add_argument("--max-shift", type=int, default=32, help="columns (64 x 256 panorama: 1.4 deg each)")
    args = p.parse_args(argv)
    rng = np.random.default_rng(args.seed)
    print(f"{args.env}, {args.steps} steps of {args.step} m, seed {args.seed}, shift search +-{args.max_shift} "
          "columns; quantiles 10/50/90 %")
    for level, params in DRIFT_LEVELS.items():
        panos, true, odom, scans = wander(args.env, OdometryNoise(**params), args.steps, args.step, args.seed)
        width = panos[0].shape[1]
        col = 2 * np.pi / width
        err = wrap_angle(odom[:, 2] - true[:, 2])  # heading error of the odometry at each step
        enc = SSIMEncoder(shortlist=None)
        for im in panos:
            enc.add(im)
        print(f"\n{level}: slip {params['slip']}, heading bias {params['heading_bias']} rad/m")
        print(f"{'true distance (m)':>18} {'pairs':>6} {'raw':>16} {'search':>16} {'true-shift':>16}"
              f" {'|true shift| cols':>18} {'|shift error| cols':>19} {'icp inliers':>16}"
              f" {'icp pos. error':>16}")
        for (lo, hi), (ii, jj) in pairs(true, args.gap, args.per_bin, rng).items():
            raw, found, oracle, tshift, serr, inl, perr = [], [], [], [], [], [], []
            for i, j in zip(ii, jj, strict=True):
                # roll(pano_j, s) lines up with pano_i when s = (err_j - err_i) / column
                s_true = int(np.round(wrap_angle(err[j] - err[i]) / col))
                raw.append(ssim(panos[j], panos[i]))
                _, s, score = enc.align(panos[j], [i], args.max_shift)
                found.append(score)
                oracle.append(ssim(np.roll(panos[j], s_true, axis=1), panos[i]))
                tshift.append(abs(s_true))
                serr.append(abs((s - s_true + width // 2) % width - width // 2))
                # C takes the points seen at j (odometry frame j) onto those seen at i
                c_true = about(wrap_angle(err[i] - err[j]), odom[j, :2],
                               odom[i, :2] + np_rot(err[i]) @ (true[j, :2] - true[i, :2]))
                init = about(-s * col, odom[j, :2], odom[j, :2])
                a = icp(odom[j, :2] + scans[j], odom[i, :2] + scans[i], init, max_distance=1.5)
                if abs(s_true) > args.max_shift:
                    continue  # heading apart beyond the search: the agent corrects before that
                inl.append(a.inliers)
                if np.hypot(*(apply(c_true, odom[j, :2]) - odom[j, :2])) <= 1.5:
                    perr.append(float(np.hypot(*(apply(a.transform, odom[j, :2]) - apply(c_true, odom[j, :2])))))
            tshift, serr = np.array(tshift), np.array(serr)
            inside = tshift <= args.max_shift
            label = f"{lo:.2f}-{hi:.2f}" if np.isfinite(hi) else f">= {lo:.1f}"
            extra = q(serr[inside]) if hi <= 1.0 else "     -    "
            print(f"{label:>18} {len(raw):>6} {q(raw):>16} {q(found):>16} {q(oracle):>16} {q(tshift):>18}"
                  f" {extra:>19} {q(inl):>16} {q(perr) if hi <= 1.0 else '-':>16} ({len(inl)}, {len(perr)})")


if __name__ == "__main__":
    main()

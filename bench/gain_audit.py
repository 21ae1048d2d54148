"""Where the unseen area that AIMAPP expects from its chosen viewpoints really lies.

AIMAPP picks the viewpoint it walks to by the unseen area it imagines from there
(``planning.sensed.unseen_area`` over its own sensed grid, unknown cells transparent up to the
``view_free_path`` discount) per metre of path. This audit replays the exploration study's AIMAPP
runs (perfect odometry, so the belief frame is the world frame) and, each time the agent takes
up a new viewpoint, sorts the area it imagined from there by what the true map holds at each
sample of the imagined view:

* **new**: reachable free space the LiDAR has not covered yet (what a view can really add);
* **seen**: reachable free space already covered;
* **occupied**: a wall, shelf or piece of furniture;
* **outside**: neither (beyond the outer walls, or free space the robot cannot reach).

It also prints the area a true 180-ray view from the viewpoint would add: the gain the oracle
ranks its own viewpoints by, with the same rule (gain per metre of path). The gap between the
imagined and the true columns is what the agent does not know of the map.

    python bench/gain_audit.py [--envs small_warehouse aisle_warehouse] [--seeds 0 1 2 3 4]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from cogmap.study.config import ALL_ENVS, STEPS_FULL

KINDS = ("new", "seen", "occupied", "outside")


def split(weights, points, grid, reachable, seen) -> dict:
    """Imagined area (m2) by what the true grid holds at each sample (``KINDS``)."""
    rc = grid.world_to_cell(points)
    inside = grid.in_bounds(rc)
    r, c = np.clip(rc[..., 0], 0, grid.shape[0] - 1), np.clip(rc[..., 1], 0, grid.shape[1] - 1)
    free = inside & reachable[r, c]
    occupied = inside & grid.occupied[r, c]
    masks = {"new": free & ~seen[r, c], "seen": free & seen[r, c], "occupied": occupied,
             "outside": ~free & ~occupied}
    return {k: float((weights * m).sum()) for k, m in masks.items()}


def audit_run(env: str, seed: int, steps: int) -> list[dict]:
    """One AIMAPP run of the exploration study (``explore_episode``); a row per viewpoint it took up."""
    from cogmap.baselines.oracle import visible_mask
    from cogmap.explore import coverage_tracker
    from cogmap.planning import sensed
    from cogmap.study.runs import explore_episode

    rows, last = [], None

    def on_step(sim, agent):  # after the planning call, before the move
        nonlocal last
        cfg, views, grid = agent.cfg, agent.memory.views, sim.grid
        v = views.pursuit.viewpoint
        if v is None or (last is not None and np.hypot(*(v - last)) <= cfg.view_keep_radius):
            return
        last = v.copy()
        tracker = coverage_tracker(sim)
        seen, reachable = tracker.seen, tracker.free  # free: reachable from the run's start
        points, weights = sensed.view_weights(views.grid, v, cfg.view_radius, cfg.view_rays,
                                              free_path=cfg.view_free_path)
        row = split(weights[0], points[0], grid, reachable, seen)
        view = visible_mask(grid.occupied, grid.origin, grid.resolution, v, 180, cfg.view_radius)
        row["true"] = float(np.count_nonzero(view & reachable & ~seen)) * grid.resolution**2
        row["imagined"] = float(weights.sum())
        rows.append(row)

    sim, _, _, _ = explore_episode(env, "aimapp", seed, steps, on_step=on_step)
    sim.close()
    return rows


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--envs", nargs="+", default=list(ALL_ENVS), choices=list(ALL_ENVS))
    ap.add_argument("--seeds", nargs="+", type=int, default=[0, 1, 2, 3, 4])
    args = ap.parse_args(argv)
    print("| layout | viewpoints taken up | imagined (m2) | new | seen | occupied | outside | "
          "true view adds (m2) |")
    print("|---|---|---|---|---|---|---|---|")
    t0 = time.perf_counter()
    for env in args.envs:
        rows = [r for s in args.seeds for r in audit_run(env, s, STEPS_FULL[env])]
        if not rows:
            print(f"| {env} | 0 | – | – | – | – | – | – |")
            continue
        im = np.array([r["imagined"] for r in rows])
        share = {k: sum(r[k] for r in rows) / im.sum() for k in KINDS}
        print(f"| {env} | {len(rows)} | {im.mean():.1f} | "
              + " | ".join(f"{share[k]:.0%}" for k in KINDS)
              + f" | {np.mean([r['true'] for r in rows]):.1f} |", flush=True)
    print(f"\n{len(args.envs)} layouts x {len(args.seeds)} seeds in {time.perf_counter() - t0:.0f} s; shares are of "
          "the imagined area summed over the viewpoints (with the view_free_path discount).")


if __name__ == "__main__":
    main()

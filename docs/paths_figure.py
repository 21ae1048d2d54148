"""Figure of docs/exploration.md: the paths of AIMAPP, the next-best-view explorer (the oracle's
rule on its own map) and the oracle tour (true map) until LiDAR coverage first reaches 90 %, in the
two layouts where AIMAPP is furthest from the oracle (the study's runs: same seeds, same starts).

    python docs/paths_figure.py     # writes docs/img/exploration/paths-to-90.png
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

OUT = Path(__file__).resolve().parent / "img" / "exploration" / "paths-to-90.png"
CASES = (("small_warehouse", 0), ("aisle_warehouse", 4))
METHODS = (("aimapp", "AIMAPP"), ("nbv", "next-best view, own map"), ("oracle", "oracle, true map"))
LEVEL = 0.9


def path_to_level(env: str, method: str, seed: int):
    """True positions (k, 2) up to the first decision at ``LEVEL`` coverage, the distance there,
    the true occupancy grid and its extent."""
    from cogmap.study.config import STEPS_FULL
    from cogmap.study.runs import explore_episode

    sim, ep, _, _ = explore_episode(env, method, seed, STEPS_FULL[env])
    try:
        g = sim.grid
        H, W = g.occupied.shape
        extent = [g.origin[0], g.origin[0] + W * g.resolution, g.origin[1], g.origin[1] + H * g.resolution]
        xy = np.array([[r["true_x"], r["true_y"]] for r in ep.rows])
        hit = np.flatnonzero(np.asarray(ep.coverage) >= LEVEL)
        k = int(hit[0]) if hit.size else len(xy) - 1
        return xy[: k + 1], float(ep.distance[k]), g.occupied, extent
    finally:
        sim.close()


def main() -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(len(CASES), len(METHODS), figsize=(13, 4.2 * len(CASES)))
    for row, (env, seed) in zip(axes, CASES, strict=True):
        for ax, (method, label) in zip(row, METHODS, strict=True):
            xy, dist, occupied, extent = path_to_level(env, method, seed)
            ax.imshow(occupied, origin="lower", extent=extent, cmap="Greys")
            ax.plot(xy[:, 0], xy[:, 1], "-o", ms=2.5, color="tab:blue")
            ax.plot(*xy[0], "*", ms=14, color="tab:green")
            ax.set_title(f"{env} seed {seed}: {label}\n{dist:.1f} m to {LEVEL:.0%} coverage", fontsize=10)
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([])
    fig.tight_layout()
    OUT.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(OUT, dpi=80)
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()

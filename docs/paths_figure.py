"""Figure of docs/exploration.md: the paths of AIMAPP, the next-best-view explorer (the oracle's
rule on its own map) and the oracle tour (true map) until LiDAR coverage first reaches 90 %, in the
two layouts where AIMAPP is furthest from the oracle (the study's runs: same seeds, same starts).

    python docs/paths_figure.py     # writes docs/img/exploration/paths-to-90.png
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from cogmap.plots import save_figure

OUT = Path(__file__).resolve().parent / "img" / "exploration" / "paths-to-90.png"
CASES = (("small_warehouse", 0), ("aisle_warehouse", 4))
METHODS = (("aimapp", "AIMAPP"), ("nbv", "next-best view, own map"), ("oracle", "oracle, true map"))


def path_to_level(env: str, method: str, seed: int):
    """The layout, the true positions (k, 2) up to the first decision at 90 % coverage
    (:func:`cogmap.study.metrics_extra.first_reach`) and the distance travelled then."""
    from cogmap.study.config import STEPS_FULL
    from cogmap.study.metrics_extra import first_reach
    from cogmap.study.runs import explore_episode

    sim, ep, _, _ = explore_episode(env, method, seed, STEPS_FULL[env])
    sim.close()
    xy = np.array([[r["true_x"], r["true_y"]] for r in ep.rows])
    k = first_reach(ep.coverage)
    k = len(xy) - 1 if k is None else k
    return sim.layout, xy[: k + 1], float(ep.distance[k])


def main() -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from cogmap.envs.render import draw_layout
    from cogmap.study.metrics_extra import COVERAGE_LEVEL

    fig, axes = plt.subplots(len(CASES), len(METHODS), figsize=(13, 4.2 * len(CASES)))
    for row, (env, seed) in zip(axes, CASES, strict=True):
        for ax, (method, label) in zip(row, METHODS, strict=True):
            layout, xy, dist = path_to_level(env, method, seed)
            draw_layout(layout, path=xy, ax=ax, show_starts=False,
                        title=f"{env} seed {seed}: {label}\n{dist:.1f} m to {COVERAGE_LEVEL:.0%} coverage")
            ax.plot(*xy[0], "*", ms=14, color="tab:green", zorder=9)
            ax.title.set_fontsize(10)
    save_figure(fig, OUT, dpi=80)
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()

"""Views alias in corridors; the pose evidence keeps the places apart.

``python docs/aliasing_figure.py [ENV]`` explores a building (default: the tutorial's L-shaped
corridor, docs/examples/building.json) with and without corridor centring
(``AgentConfig.passage_width``), then draws docs/img/aliasing/corridor.png and prints the numbers
the docs quote:

* the two maps, the visited states whose view (observation id) is tied to another state too
  outlined in red and coloured by that view, so states of one colour are ones the encoder cannot
  tell apart;
* for every pair of visited states, the SSIM of their stored panoramas (as the encoder compares
  views) against the distance between their stored poses, with the
  recognition threshold, and the pose likelihood A_p of the same distance (Gaussian of width
  ``influence_radius / 3``): views 1-3 m apart along a corridor often pass the threshold, while
  the pose evidence of a state 1 m away is already exp(-4.5) of the nearest one's.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from cogmap.agent.aimapp import AIMAPPAgent  # noqa: E402
from cogmap.agent.encoder import ssim  # noqa: E402
from cogmap.envs.render import draw_layout  # noqa: E402
from cogmap.explore import default_config, make_sim, resolve_layout, run_agent  # noqa: E402

ENV, SEED, STEPS = "docs/examples/building.json", 0, 120
OUT = Path(__file__).resolve().parent / "img" / "aliasing" / "corridor.png"


def explore(passage_width: float):
    """The agent after a seeded exploration of ``ENV`` with ``passage_width``."""
    cfg = replace(default_config(ENV), passage_width=passage_width)
    sim = make_sim(ENV, cfg, SEED)
    try:
        agent = AIMAPPAgent(cfg, seed=SEED)
        run_agent(sim, agent, STEPS, progress=False)
        return agent
    finally:
        sim.close()


def view_of(agent) -> dict[int, int]:
    """Visited state -> the observation id most tied to it."""
    counts = np.array([agent.model.pA_row(0, o) for o in range(agent.model.num_obs[0])])  # (obs, states)
    return {int(s): int(np.argmax(counts[:, s])) for s in np.flatnonzero(agent.visited())}


def pair_similarity(agent) -> tuple[np.ndarray, np.ndarray]:
    """Distances (m) and panorama SSIM (as the encoder compares them, in the belief frame) of every
    pair of anchored states."""
    states = sorted(agent.memory.anchors)
    d, s = [], []
    for i, a in enumerate(states):
        for b in states[i + 1:]:
            d.append(float(np.hypot(*(agent.poses[a] - agent.poses[b]))))
            s.append(ssim(agent.memory.anchors[a].panorama, agent.memory.anchors[b].panorama))
    return np.array(d), np.array(s)


def main(argv=None) -> None:
    global ENV
    import sys

    args = sys.argv[1:] if argv is None else argv
    if args:
        ENV = args[0]
    layout = resolve_layout(ENV)
    runs = {"centred (passage_width 2.5 m)": explore(2.5), "the paper's placement (passage_width 0)": explore(0.0)}
    fig, axes = plt.subplots(1, 3, figsize=(21, 5.6), gridspec_kw={"width_ratios": [1.3, 1.3, 1]})
    for ax, (label, agent) in zip(axes[:2], runs.items(), strict=True):
        draw_layout(layout, ax=ax, title="")
        views = view_of(agent)
        ids = np.array(list(views.values()))
        poses = agent.poses[list(views)]
        shared = np.array([np.count_nonzero(ids == i) > 1 for i in ids])
        ax.scatter(poses[~shared, 0], poses[~shared, 1], c="0.85", s=40, edgecolors="k", zorder=5,
                   label="view of its own")
        ax.scatter(poses[shared, 0], poses[shared, 1], c=ids[shared] % 10, cmap="tab10", s=70, edgecolors="r",
                   linewidths=2, zorder=6, label="view shared with another state (same colour)")
        ax.legend(loc="lower right", fontsize=8)
        ax.set_title(f"{label}:\n{len(views)} visited states, {len(set(ids))} distinct views "
                     f"({len(set(ids)) / len(views):.2f} per state)", fontsize=10)
        print(f"{label}: states {agent.num_states}, visited {len(views)}, distinct views {len(set(ids))}")
    agent = runs["centred (passage_width 2.5 m)"]
    d, s = pair_similarity(agent)
    ax = axes[2]
    ax.scatter(d, s, s=8, alpha=0.5, label="pairs of visited states: panorama SSIM")
    ax.axhline(agent.cfg.ssim_threshold, color="C3", ls="--", label=f"recognition threshold {agent.cfg.ssim_threshold}")
    x = np.linspace(0, max(6.0, float(d.max()) if d.size else 6.0), 200)
    ax.plot(x, np.exp(-x**2 / (2 * agent.cfg.sigma**2)), "k-", label="pose likelihood A_p (relative), width r/3")
    ax.set_xlabel("distance between the two states' stored poses (m)")
    ax.set_ylim(0, 1.02)
    ax.set_xlim(0, 8)
    ax.legend(loc="upper right", fontsize=8)
    close = (d >= 0.9) & (d <= 3.0)
    above = int((s[close] >= agent.cfg.ssim_threshold).sum())
    ax.set_title(f"{ENV}: pairs 0.9-3 m apart,\n{above} of {int(close.sum())} pass the threshold", fontsize=10)
    print(f"pairs 0.9-3 m apart: {above} of {int(close.sum())} above the SSIM threshold; "
          f"pose likelihood at 1 m: {np.exp(-1.0 / (2 * agent.cfg.sigma**2)):.4f}")
    OUT.parent.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(OUT, dpi=70)
    print(OUT)


if __name__ == "__main__":
    main()

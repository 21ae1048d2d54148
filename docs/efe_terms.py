"""Figure of docs/exploration.md: what each EFE term contributes to each decision of a house
exploration (seed 0), beside the LiDAR coverage.

    python docs/efe_terms.py                  # writes docs/img/exploration/efe-terms.png
    python bench/exploration.py --figure PATH # the same figure, elsewhere
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

OUT = Path(__file__).resolve().parent / "img" / "exploration" / "efe-terms.png"


def record(env: str = "house", seed: int = 0, steps: int = 120):
    """Per decision: the weighted first-step contribution of every term (to G) for the chosen
    action, the MCTS value of that action, the coverage and whether a target was preferred."""
    from cogmap.agent.aimapp import AIMAPPAgent
    from cogmap.agent.planner import term_breakdown
    from cogmap.explore import coverage_tracker, default_config, make_sim, run_agent

    cfg = default_config(env)
    sim = make_sim(env, cfg, seed)
    rows = []
    try:
        agent = AIMAPPAgent(cfg, seed=seed)
        tracker = coverage_tracker(sim)

        def on_step(d):
            if "objective" not in d.efe:
                return
            terms = term_breakdown(agent, d.efe, d.action)
            i = int(np.flatnonzero(np.asarray(d.efe["actions"]) == d.action)[0])
            pref = d.efe.get("preferred")
            rows.append({"terms": terms, "Q": float(d.efe["Q"][i]), "coverage": tracker.coverage,
                         "target": -1 if pref is None or len(pref) == 0 else int(pref[0])})

        ep = run_agent(sim, agent, steps, progress=False, on_step=on_step)
        return rows, ep
    finally:
        sim.close()


def draw(path=OUT, env: str = "house", seed: int = 0, steps: int = 120) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows, ep = record(env, seed, steps)
    names = sorted({k for r in rows for k in r["terms"]})
    x = np.arange(len(rows))
    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(11, 6.5), sharex=True, gridspec_kw={"height_ratios": [2, 1]})
    colours = {"sensed_info_gain": "tab:blue", "inductive": "tab:orange", "collision": "tab:red",
               "state_info_gain": "tab:green", "param_info_gain": "tab:purple"}
    bottom_neg = np.zeros(len(rows))
    bottom_pos = np.zeros(len(rows))
    for n in names:
        v = np.array([r["terms"].get(n, 0.0) for r in rows])
        neg, pos = np.minimum(v, 0), np.maximum(v, 0)
        ax.bar(x, neg, bottom=bottom_neg, color=colours.get(n), label=n, width=0.9)
        ax.bar(x, pos, bottom=bottom_pos, color=colours.get(n), width=0.9)
        bottom_neg += neg
        bottom_pos += pos
    ax.plot(x, [r["Q"] / 10 for r in rows], "k.", ms=3, label="MCTS value of the action / 10 (depth 10)")
    ax.axhline(0, color="k", lw=0.5)
    ax.set_ylabel("contribution to G (first step)\nnegative = attractive")
    ax.legend(loc="lower right", fontsize=8, ncol=2)
    ax.set_title(f"EFE terms of the chosen action per decision, AIMAPP exploring the {env} (seed {seed})")
    cov = np.array([r["coverage"] for r in rows])
    ax2.plot(x, cov, "k-", label="LiDAR coverage")
    no_target = np.array([r["target"] < 0 for r in rows])
    ax2.fill_between(x, 0, 1, where=no_target, color="0.85", step="mid",
                     label="no viewpoint pursued: paper terms only")
    ax2.axhline(0.9, color="tab:gray", ls="--", lw=0.8)
    ax2.set_ylim(0, 1.02)
    ax2.set_xlabel("decision")
    ax2.set_ylabel("coverage")
    ax2.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    hit = np.flatnonzero(np.asarray(ep.coverage) >= 0.9)
    summary = {"decisions": len(rows), "coverage_end": float(ep.coverage[-1]),
               "distance_at_90_m": None if hit.size == 0 else float(ep.distance[int(hit[0])])}
    path.with_suffix(".json").write_text(json.dumps(summary, indent=1))
    print(path, summary)
    return path


if __name__ == "__main__":
    draw()

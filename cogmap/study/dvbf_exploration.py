"""The DVBF-LM exploration study (``cogmap reproduce dvbf-exploration``; paper Section VI, Table II, Figure 9).

One run = one method (``mi``, ``mi-pull``, ``random``, ``frontier``; :mod:`cogmap.dvbf.explore`) in one seeded
maze of one Table II row, from the same seeded start for every method. The environment name is the row,
``<complexity>-<corridor>``; study seed ``s`` explores maze ``s + 1`` (maze 0 pretrains the emission).
The exploration ratio is read at the step budget of the plan (the paper's Table II budget unless the
scale shortens it, which the report says).

The paper gives its results only as curves (Figure 9: infogain and exploration ratio over time,
aggregated over mazes of all complexities, seven runs, against the LSTM baseline PEMA); no numbers are
printed, so the table lists the paper's budgets and tiles beside our measurements. PEMA needs a policy
trained by Augmented Random Search and is not included. ``mi-pull`` is the DVBF-LM agent with our frontier
pull (``MIConfig.pull_below``, recorded in the run's ``method_options`` and so in its key); ``mi`` runs the
paper's procedure without it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

NAME = "dvbf-exploration"
METHODS = ("mi", "mi-pull", "random", "frontier")  # as cogmap.dvbf.explore.RUN_METHODS (not imported: jax)
LABEL = {"mi": "DVBF-LM (MI)", "mi-pull": "DVBF-LM (MI + frontier pull, ours)", "random": "random walk",
         "frontier": "frontier (true LiDAR, true poses)"}
MI_METHODS = ("mi", "mi-pull")
ALL_LEVELS = tuple(f"{c}-{w}" for c in ("simple", "moderate", "complex") for w in ("small", "medium", "large"))
#: reduced scale: the smallest maze of each complexity level, a short fixed budget (the full scale runs every
#: Table II row at its budget, up to 18,000 steps; the MI agent takes about 0.1 s a step on this machine)
REDUCED_LEVELS = ("simple-small", "moderate-small", "complex-small")
REDUCED_STEPS = 200


# what the report's columns measure (its note begins with this)
MEASURES = ("Exploration ratio: fraction of the Table II tiles visited by the true positions at the budget. "
            "Information gain: KL(q(M) || p(M)) of the agent's map at the end (paper Appendix D); the baselines "
            "learn no map in this study. Planning call: one whole MI planning step (obstacle penalty from the "
            "learnt map, candidate optimisation, MI of every candidate), wall clock on this shared 2-core machine. "
            "MI settings of the study (not the paper's, which are about 100 times heavier):")


def level_of(env: str) -> tuple[str, str]:
    """``"moderate-small"`` -> ``("moderate", "small")``, with a clear error for an unknown row."""
    if env not in ALL_LEVELS:
        raise ValueError(f"dvbf-exploration environments are Table II rows {list(ALL_LEVELS)}, got {env!r}")
    c, w = env.split("-")
    return c, w


def budget(env: str) -> int:
    from cogmap.envs.maze import TABLE_II

    return TABLE_II[level_of(env)][2]


def dvbf_exploration_plan(scale: str, seeds=None, methods=None, envs=None) -> dict:
    from cogmap.dvbf.explore import STUDY_MI, ExploreConfig

    envs = list(envs) if envs is not None else list(ALL_LEVELS if scale == "full" else
                                                     REDUCED_LEVELS if scale == "reduced" else REDUCED_LEVELS[:1])
    for e in envs:
        level_of(e)
    methods = list(methods) if methods is not None else list(METHODS)
    bad = [m for m in methods if m not in METHODS]
    if bad:
        raise ValueError(f"unknown dvbf-exploration method(s) {bad}; choose from {list(METHODS)}")
    mi = ExploreConfig(mi=STUDY_MI)
    return {"study": NAME, "scale": scale, "stop_rule": "step budget (Table II)", "coverage_level": None,
            "success_rule": None, "aimapp_patience": None, "envs": envs, "methods": methods,
            "seeds": list(seeds) if seeds is not None else list(range({"full": 7, "reduced": 5}.get(scale, 1))),
            "steps": {e: budget(e) if scale == "full" else REDUCED_STEPS if scale == "reduced" else 60 for e in envs},
            "params": {"config": mi.to_json(), "pretrain": {"maze": 0, "steps": 2000, "iters": 1500}}}


def dvbf_exploration_specs(plan: dict) -> list[dict]:
    from cogmap.dvbf.explore import PULL_BELOW

    from .config import spec_digest

    specs = []
    for env in plan["envs"]:
        for method in plan["methods"]:
            for seed in plan["seeds"]:
                spec = {"study": NAME, "scale": plan["scale"], "env": env, "method": method, "seed": int(seed),
                        "level": None, "noise": None, "steps": plan["steps"][env], "stop_rule": plan["stop_rule"],
                        "coverage_level": None, "success_rule": None,
                        "method_options": {"pull_below": PULL_BELOW} if method == "mi-pull" else {},  # in the key
                        "params": plan["params"]}
                specs.append({"key": f"{env}__{method}__s{seed}__{spec_digest(spec)}", **spec})
    return specs


def run_dvbf_exploration(spec: dict) -> dict:
    from cogmap.dvbf.explore import ExploreConfig, cache_dir, explore, pretrained_emission
    from cogmap.envs.maze import make_maze
    from cogmap.planning.mi_exploration import MIConfig

    c, w = level_of(spec["env"])
    maze = make_maze(spec["seed"] + 1, c, w)
    cfg = dict(spec["params"]["config"])
    cfg["mi"] = MIConfig(**{**cfg["mi"], **spec["method_options"]})
    cfg.update(method="mi" if spec["method"] in MI_METHODS else spec["method"], seed=spec["seed"])
    cfg = ExploreConfig(**cfg)
    emission = None
    if cfg.method == "mi" or cfg.learn_map:
        p = spec["params"]["pretrain"]
        emission = pretrained_emission(cache_dir(), steps=p["steps"], iters=p["iters"])
    res = explore(maze, spec["steps"], cfg, emission=emission)
    out = res.metrics(spec["steps"])
    out["maze_seed"] = maze.seed
    out["tiles"] = maze.tiles
    # timing fields end in _s or _ms (strip_timings drops them in comparisons)
    out["plan_call_s"] = [round(x, 4) for x in res.plan_seconds]
    out["run_wall_s"] = out.pop("run_s")
    return out


def _f(x, d=2) -> str:
    return "–" if x is None else f"{x:.{d}f}"


def dvbf_exploration_report(study_dir: Path, plan, results) -> str:
    from cogmap.envs.maze import TABLE_II
    from cogmap.envs.maze_episode import ratio_at

    from .tables import md_table, pyplot, save_figure, write_csv

    study_dir = Path(study_dir)
    rows, csv_rows, per_run = [], [], []
    verdict = {}
    for env in plan["envs"]:
        c, w = level_of(env)
        side, tiles, paper_steps = TABLE_II[(c, w)]
        steps = plan["steps"][env]
        by = {m: sorted((r for r in results if r["spec"]["env"] == env and r["spec"]["method"] == m),
                        key=lambda r: r["spec"]["seed"]) for m in plan["methods"]}
        rows.append([env, f"{paper_steps} steps, {tiles} x {tiles} tiles", "paper: Figure 9 only (no numbers); "
                     "PEMA (LSTM, ARS-trained): not included", "–", "–", "–", "–", "–", "–"])
        for m in plan["methods"]:
            rs = by[m]
            if not rs:
                continue
            ratios = np.array([r["result"]["ratio_final"] for r in rs])
            early = {f: np.array([ratio_at(r["result"]["ratio_curve"], int(f * (steps - 1))) for r in rs])
                     for f in (0.25, 0.5)}
            info = [r["result"]["info_gain_final"] for r in rs if r["result"]["info_gain_final"] is not None]
            plan_ms = [1000 * r["result"]["plan_call_median_s"] for r in rs if r["result"]["plan_call_median_s"]]
            rows.append([env, f"{steps} steps", LABEL[m], f"{len(rs)}", f"{early[0.25].mean():.3f}",
                         f"{early[0.5].mean():.3f}", f"{ratios.mean():.3f} ± {ratios.std():.3f}",
                         _f(np.mean(info), 0) if info else "–", _f(np.median(plan_ms), 0) if plan_ms else "–"])
            csv_rows.append([env, steps, paper_steps, tiles, m, len(rs), round(float(ratios.mean()), 4),
                             round(float(ratios.std()), 4), round(float(np.mean(info)), 2) if info else "",
                             round(float(np.median(plan_ms)), 1) if plan_ms else ""])
            for r in rs:
                per_run.append([env, m, r["spec"]["seed"], r["result"]["maze_seed"], steps,
                                round(r["result"]["ratio_final"], 4),
                                _f(r["result"]["info_gain_final"], 1) if r["result"]["info_gain_final"] else "",
                                r["result"]["blocked_steps"], round(r["result"]["path_length"], 3)])
        for mi in (m for m in MI_METHODS if by.get(m) and by.get("random")):
            pairs = {r["spec"]["seed"]: r["result"]["ratio_final"] for r in by["random"]}
            wins = [r["result"]["ratio_final"] > pairs[r["spec"]["seed"]] for r in by[mi]
                    if r["spec"]["seed"] in pairs]
            mi_mean = np.mean([r["result"]["ratio_final"] for r in by[mi]])
            rw_mean = np.mean(list(pairs.values()))

            def at(rs, f, steps=steps):
                return np.mean([ratio_at(r["result"]["ratio_curve"], int(f * (steps - 1))) for r in rs])

            paired = [(r["result"]["ratio_final"], pairs[r["spec"]["seed"]]) for r in by[mi]
                      if r["spec"]["seed"] in pairs]
            pulled = [r["result"]["pulled_plans"] / max(r["result"]["plan_calls"], 1) for r in by[mi]
                      if r["result"].get("pulled_plans") is not None and mi == "mi-pull"]
            verdict.setdefault(mi, []).append(
                (c, (np.array([p[0] for p in paired]), np.array([p[1] for p in paired])),
                 f"- {env}, {LABEL[mi]}: above the random walk in {sum(wins)} of {len(wins)} paired seeds "
                 f"(ties count as not above); earlier, mean {at(by[mi], 0.25):.3f} vs "
                 f"{at(by['random'], 0.25):.3f} at 1/4 of the budget and {at(by[mi], 0.5):.3f} vs "
                 f"{at(by['random'], 0.5):.3f} at 1/2; at the budget mean {mi_mean:.3f} vs {rw_mean:.3f} "
                 f"({'above' if mi_mean > rw_mean else 'not above'})"
                 + (f"; planning calls that took the frontier pull: {100 * np.mean(pulled):.0f} % (mean over runs)"
                    if pulled else "")))
    header = ["Table II row", "budget", "method", "runs", "ratio at 1/4 budget", "ratio at 1/2 budget",
              "exploration ratio at the budget (mean ± std)",
              "information gain KL(q(M) || p(M)) at the end (nats)", "planning call median (ms)"]
    write_csv(study_dir / "table.csv", ["env", "steps", "paper_steps", "tiles", "method", "runs", "ratio_mean",
                                   "ratio_std", "info_gain_mean", "plan_call_median_ms"], csv_rows)
    write_csv(study_dir / "runs.csv", ["env", "method", "seed", "maze_seed", "steps", "ratio", "info_gain",
                                  "blocked_steps", "path_length"], per_run)
    plt = pyplot()
    fig, axes = plt.subplots(1, len(plan["envs"]), figsize=(4.5 * len(plan["envs"]), 3.6), squeeze=False)
    colours = {"mi": "tab:blue", "mi-pull": "tab:purple", "random": "tab:red", "frontier": "tab:green"}
    for ax, env in zip(axes[0], plan["envs"], strict=True):
        for m in plan["methods"]:
            curves = [np.array(r["result"]["ratio_curve"]) for r in results
                      if r["spec"]["env"] == env and r["spec"]["method"] == m]
            if not curves:
                continue
            n = min(len(cv) for cv in curves)
            st = curves[0][:n, 0]
            ys = np.array([cv[:n, 1] for cv in curves])
            ax.plot(st, ys.mean(0), c=colours[m], label=LABEL[m])
            ax.fill_between(st, ys.mean(0) - ys.std(0), ys.mean(0) + ys.std(0), color=colours[m], alpha=0.2)
        ax.set_title(env)
        ax.set_xlabel("step")
        ax.set_ylim(0, 1.02)
        ax.set_ylabel("exploration ratio")
        ax.legend(fontsize=7)
    save_figure(fig, study_dir / "ratio.png", dpi=100)
    note = f"{MEASURES} {asdict_short(plan)}. Mean ± std over seeds; the shaded band in ratio.png is one std."
    if "mi-pull" in plan["methods"]:
        from cogmap.dvbf.explore import PULL_BELOW
        from cogmap.planning.mi_exploration import MIConfig

        d = MIConfig()
        note += (f" {LABEL['mi-pull']}: the same agent and settings, but when no candidate's MI reaches {PULL_BELOW} "
                 "nats it follows the cheapest path on its own sensed grid (its estimated poses and the scans it "
                 f"received there; cells of {d.pull_cell}, a wall where at least {d.pull_hit_min} returns ended, "
                 f"passable where at least {d.pull_min_crossed} beams crossed) to the nearest frontier of that grid "
                 "(cogmap.planning.frontier_pull); our addition, not the paper's.")
    missing = [e for e in ALL_LEVELS if e not in plan["envs"]]
    if missing:
        note += (f" Table II rows not run in this study directory: {', '.join(missing)}"
                 + (" (their budgets run to 18,000 steps)." if plan["scale"] == "full" else "."))
    levels = sorted({level_of(e)[0] for e in plan["envs"]})
    target = []
    for mi, vs in verdict.items():
        won = {}
        for lv in levels:  # pooled over the level's rows: every paired run of the level counts once
            pairs = [p for c, p, _ in vs if c == lv]
            if pairs:
                ours, theirs = np.concatenate([p[0] for p in pairs]), np.concatenate([p[1] for p in pairs])
                won[lv] = f"{ours.mean():.3f} vs {theirs.mean():.3f}, " + (
                    "above" if ours.mean() > theirs.mean() else "not above")
        n_above = sum(v.endswith(" above") and not v.endswith("not above") for v in won.values())
        target.append(f"**Target: MI above the random walk in every complexity level** ({LABEL[mi]}; mean "
                      f"exploration ratio at the budget over the level's paired runs, all its rows pooled; each "
                      f"row's runs are distinct seeds, one run each): {n_above} of {len(levels)} levels ("
                      + "; ".join(f"{lv}: {won.get(lv, 'no runs')}" for lv in levels) + ").")
        target.append("\n".join(v for _, _, v in vs))
    target = "\n\n".join(target)
    return (md_table(header, rows) + "\n\n" + target + "\n\n" + note
            + "\n\n![exploration ratio](ratio.png)\n")


def asdict_short(plan) -> str:
    mi = plan["params"]["config"]["mi"]
    return ", ".join(f"{k} = {mi[k]}" for k in ("horizon", "n_candidates", "n_marginal", "n_maps", "n_per_map",
                                                "opt_iters", "obs_every", "dim", "steer_only", "feasible_only",
                                                "scan_margin", "collision_level") if k in mi) + \
        f", re-plan every {plan['params']['config']['replan_every']} steps"


"""The drone study (``cogmap reproduce drone``): seeded episodes in one pybullet field for the
hierarchical agent, its ablations and two baselines, with collisions non-terminal (as the original)
and terminal (the honest setting). One run = one episode of one method in one setting, so the study
resumes per episode and runs on the local or Ray executors like the others.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

METHODS = ("agent", "agent_published", "straight", "potential", "no_filter", "no_epistemic", "no_novelty",
           "agent_persistent", "agent_depth2", "agent_depth3")
LEVELS = {"continue": False, "end": True}  # does a collision end the episode?
FIELD_SEED = 0
EPISODES = {"full": 149, "reduced": 20, "tiny": 2}

# DRONE.md 2.7, recomputed from the published CSVs (149 episodes, collisions non-terminal)
PAPER = {"success": 93.3, "collision_free_success": 46.3, "stuck": 6.0, "timeout": 0.7,
         "replans_success": 1.56, "replans_failure": 10.60, "steps_median": 16, "collisions_per_episode": 184 / 149,
         "plan_ms_median": 5.0, "plan_ms_p95": 8.6}


def drone_plan(scale: str, seeds=None, methods=None, envs=None) -> dict:
    """Episodes are the study's seeds (episode i: target from ``default_rng([field seed, i])``)."""
    from .metrics_extra import COVERAGE_LEVEL, SuccessRule

    plan = {"study": "drone", "scale": scale, "stop_rule": "success (<= 1.5 m), stuck 15 s, 250 s or 250 steps",
            "coverage_level": COVERAGE_LEVEL, "success_rule": SuccessRule().to_dict(), "aimapp_patience": None,
            "envs": [f"field{FIELD_SEED}"], "methods": list(METHODS), "seeds": list(range(EPISODES[scale])),
            "steps": {f"field{FIELD_SEED}": 250}, "params": {"levels": list(LEVELS)}}
    if scale == "tiny":
        plan["methods"] = ["agent", "straight"]
    if seeds is not None:
        plan["seeds"] = list(seeds)
    if methods is not None:
        unknown = [m for m in methods if m not in METHODS]
        if unknown:
            raise ValueError(f"unknown drone method(s) {unknown}; choose from {list(METHODS)}")
        plan["methods"] = list(methods)
    if envs is not None:
        bad = [e for e in envs if not (e.startswith("field") and e[5:].isdigit())]
        if bad:
            raise ValueError(f"drone study environments are 'field<seed>', got {bad}")
        plan["envs"] = list(envs)
        plan["steps"] = {e: 250 for e in envs}
    return plan


def drone_specs(plan: dict) -> list[dict]:
    """One spec per (field, method, setting, episode). A spec's method options are the episode
    limits and the settings of that method's own policy (``settings()``), so changing the agent
    changes the keys of the agent's runs and leaves the baselines' runs valid."""
    from dataclasses import asdict

    from cogmap.drone.methods import make_policy
    from cogmap.envs.drone_episode import EpisodeLimits

    from .config import spec_digest

    specs = []
    for env in plan["envs"]:
        for method in plan["methods"]:
            options = {"limits": asdict(EpisodeLimits()), "policy": make_policy(method).settings()}
            for level in plan["params"]["levels"]:
                for seed in plan["seeds"]:
                    spec = {"study": "drone", "scale": plan["scale"], "env": env, "method": method, "seed": int(seed),
                            "level": level, "noise": None, "steps": plan["steps"][env], "stop_rule": plan["stop_rule"],
                            "coverage_level": plan["coverage_level"], "success_rule": plan["success_rule"],
                            "method_options": options, "params": plan["params"]}
                    specs.append({"key": f"{env}__{method}__s{seed}__{level}__{spec_digest(spec)}", **spec})
    return specs


_SIMS: dict = {}


def _sim(field_seed: int, end_on_collision: bool):
    """One simulator per (field, setting) per process: building 1,300 bodies takes a while."""
    from cogmap.envs.drone_sim import DroneConfig, DroneSim

    key = (field_seed, end_on_collision)
    if key not in _SIMS:
        _SIMS[key] = DroneSim(field_seed, DroneConfig(end_on_collision=end_on_collision))
    return _SIMS[key]


def run_drone(spec: dict) -> dict:
    from cogmap.drone.methods import make_policy
    from cogmap.drone.run import episode_target
    from cogmap.envs.drone_episode import fly_episode

    field_seed = int(spec["env"][5:])
    sim = _sim(field_seed, LEVELS[spec["level"]])
    tgt = episode_target(sim, field_seed, spec["seed"])
    ep = fly_episode(sim, make_policy(spec["method"], seed=[field_seed, spec["seed"]]), tgt)
    # timing fields end in _ms / _us (cogmap.study.runs.strip_timings drops them for comparisons)
    ep["plan_call_ms"] = ep.pop("plan_ms")
    ep["plan_call_median_ms"] = ep.pop("plan_ms_median")
    ep["plan_call_p95_ms"] = ep.pop("plan_ms_p95")
    ep["efe_per_candidate_us"] = ep.pop("efe_us_per_candidate_median")
    return ep


def _pct(x) -> str:
    return "–" if x is None else f"{100 * x:.1f}"


def _f(x, d=2) -> str:
    return "–" if x is None else f"{x:.{d}f}"


def summarise_runs(rs: list[dict]) -> dict:
    from cogmap.envs.drone_episode import summarise

    eps = [{**r["result"], "plan_ms": r["result"]["plan_call_ms"],
            "efe_us_per_candidate_median": r["result"]["efe_per_candidate_us"]} for r in rs]
    return summarise(eps)


HEADER = ["method", "episodes", "success %", "collision-free success %", "stuck %", "timeout %", "crashed %",
          "collisions / episode", "episodes with a collision", "replans (success)", "replans (failure)",
          "median steps", "mean final distance (m)", "planning call median (ms)", "planning call p95 (ms)",
          "EFE per candidate (µs)"]


def drone_report(study_dir: Path, plan, results) -> str:
    from .tables import md_table, pyplot, save_figure, write_csv

    study_dir = Path(study_dir)
    out = []
    csv_rows = []
    summaries: dict = {}
    for level in plan["params"]["levels"]:
        rows = []
        if level == "continue":
            P = PAPER
            rows.append(["paper (AirSim, 149 episodes)", 149, _f(P["success"], 1), _f(P["collision_free_success"], 1),
                         _f(P["stuck"], 1), _f(P["timeout"], 1), "–", _f(P["collisions_per_episode"]), 80,
                         _f(P["replans_success"]), _f(P["replans_failure"]), P["steps_median"], "–",
                         _f(P["plan_ms_median"], 1), _f(P["plan_ms_p95"], 1), "–"])
        for env in plan["envs"]:
            for method in plan["methods"]:
                rs = [r for r in results if r["spec"]["method"] == method and r["spec"]["level"] == level
                      and r["spec"]["env"] == env]
                if not rs:
                    continue
                s = summarise_runs(rs)
                summaries[(level, method)] = s
                name = method if len(plan["envs"]) == 1 else f"{method} ({env})"
                timed = method not in ("straight", "potential")
                rows.append([name, s["episodes"], _pct(s["success_rate"]), _pct(s["collision_free_success_rate"]),
                             _pct(s["stuck_rate"]), _pct(s["timeout_rate"]), _pct(s["crashed_rate"]),
                             _f(s["collisions_per_episode"]), s["episodes_with_collision"],
                             _f(s["replans_success_mean"]), _f(s["replans_failure_mean"]), _f(s["steps_median"], 1),
                             _f(s["final_distance_mean"]), _f(s["plan_ms_median"]) if timed else "–",
                             _f(s["plan_ms_p95"]) if timed else "–",
                             _f(s["efe_us_per_candidate_median"]) if timed else "–"])
        title = ("Collisions counted, episodes go on (as the original)" if level == "continue"
                 else "Collisions end the episode (the honest setting)")
        out.append(f"## {title}\n\n" + md_table(HEADER, rows))
        csv_rows += [[level, *r] for r in rows]
    write_csv(study_dir / "table.csv", ["collisions", *HEADER], csv_rows)
    per_run = []
    for r in sorted(results, key=lambda r: (r["spec"]["level"], r["spec"]["method"], r["spec"]["seed"])):
        e, sp = r["result"], r["spec"]
        per_run.append([sp["level"], sp["method"], sp["seed"], e["outcome"], e["collisions"], e["replans"], e["steps"],
                        round(e["initial_distance"], 2), round(e["final_distance"], 2), e["fallback_steps"],
                        round(e["plan_call_median_ms"], 3)])
    write_csv(study_dir / "runs.csv", ["collisions", "method", "episode", "outcome", "collisions_count", "replans",
                                       "steps", "initial_distance_m", "final_distance_m", "fallback_steps",
                                       "plan_call_median_ms"], per_run)
    plt = pyplot()
    fig, axes = plt.subplots(1, len(plan["params"]["levels"]), figsize=(6 * len(plan["params"]["levels"]), 4),
                             squeeze=False)
    for ax, level in zip(axes[0], plan["params"]["levels"], strict=True):
        ms = [m for m in plan["methods"] if (level, m) in summaries]
        x = np.arange(len(ms))
        ax.bar(x - 0.2, [100 * summaries[(level, m)]["success_rate"] for m in ms], 0.4, label="success")
        ax.bar(x + 0.2, [100 * summaries[(level, m)]["collision_free_success_rate"] for m in ms], 0.4,
               label="collision-free success")
        ax.set_xticks(x, ms, rotation=30, ha="right")
        ax.set_ylim(0, 100)
        ax.set_ylabel("% of episodes")
        ax.set_title("collisions go on" if level == "continue" else "collisions end the episode")
        if level == "continue":
            ax.axhline(PAPER["success"], c="tab:blue", ls="--", lw=0.8)
            ax.axhline(PAPER["collision_free_success"], c="tab:orange", ls="--", lw=0.8)
        ax.legend(fontsize=8)
    save_figure(fig, study_dir / "success.png", dpi=100)
    note = ("Success = final distance <= 1.5 m; stuck = the drone stayed within 1 m of where it was 15 s earlier; "
            "timeout = 250 simulated seconds or 250 steps; crashed = a collision with collisions ending the episode. "
            "Replans = in-flight replanning because an obstacle came within 2 m, mean over successful and failed "
            "episodes. Planning call = one whole decision (beliefs, candidates, suitability, filter, EFE, ranking), "
            "wall clock on this machine; the paper's figure is a ZMQ round trip on 4 cores. The paper's world "
            "(AirSim Neighborhood), sensor and controller differ from ours: compare the pattern, not the digits "
            "(DRONE.md 2.9).")
    return "\n\n".join(out) + "\n\n" + note + "\n\n![success](success.png)\n"

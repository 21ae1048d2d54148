"""One study run = a pure function of its spec (study, env, method, seed, config) returning a
JSON-able dict. Runs are deterministic per seed except the fields ending in ``_ms`` /
``_s`` (wall-clock timings)."""

from __future__ import annotations

import copy
import math
import tempfile
from dataclasses import replace
from pathlib import Path

import numpy as np

from .metrics_extra import (
    SuccessRule,
    drift_metrics,
    endpoints,
    graph_plan_length,
    interventions,
    nauc_budget,
    path_length_ratios,
    trajectory_digest,
    transitions_into,
)

TIMING_SUFFIXES = ("_ms", "_s", "_us")


def clean_json(x):
    """numpy scalars/arrays -> Python; non-finite floats -> None (strict JSON)."""
    if isinstance(x, dict):
        return {str(k): clean_json(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [clean_json(v) for v in x]
    if isinstance(x, np.ndarray):
        return clean_json(x.tolist())
    if isinstance(x, np.generic):
        x = x.item()
    if isinstance(x, float) and not math.isfinite(x):
        return None
    return x


def _noise(spec):
    from cogmap.envs import OdometryNoise

    return OdometryNoise(**spec["noise"]) if spec.get("noise") else None


def _faults(spec) -> list[tuple[str, int, int]]:
    """The dropout study's silent stream: ``(stream, first silent decision, length)``, or none."""
    if spec["study"] != "dropout" or spec["level"] in (None, "none"):
        return []
    return [(spec["level"], spec["params"]["fault_start"], spec["params"]["fault_length"])]


def study_sim(env: str, cfg, seed: int, noise=None):
    """A simulator whose start is seed ``seed``'s own (``cogmap.starts.seed_start`` via
    ``cogmap.explore.make_sim``): every seed starts somewhere else, as in the paper."""
    from cogmap.explore import make_sim

    return make_sim(env, cfg, seed, noise)


def study_agent(spec):
    """The AIMAPP agent of a room spec (its room's default config and seed) and its
    :func:`study_sim`; the caller closes the simulator."""
    from cogmap.agent.aimapp import AIMAPPAgent
    from cogmap.explore import default_config

    cfg = default_config(spec["env"])
    sim = study_sim(spec["env"], cfg, spec["seed"])
    try:
        return AIMAPPAgent(cfg, seed=spec["seed"]), sim
    except BaseException:
        sim.close()
        raise


def _curve(ep, points: int = 120) -> dict:
    d, c = np.asarray(ep.distance), np.asarray(ep.coverage)
    idx = np.unique(np.linspace(0, len(d) - 1, min(points, len(d))).round().astype(int))
    return {"distance": [round(float(v), 3) for v in d[idx]], "coverage": [round(float(v), 4) for v in c[idx]]}


def make_policy(method: str, sim, step: float, seed: int, config: dict | None = None):
    """The baseline policy of ``method`` with the simulator's robot and LiDAR; ``config`` (the
    spec's ``method_options["config"]``) overrides the config dataclass's defaults."""
    from cogmap.baselines import (
        FrontierConfig,
        FrontierExplorer,
        FrontierPaperConfig,
        FrontierPaperExplorer,
        NBVConfig,
        NextBestView,
        OracleConfig,
        OracleTour,
        RandomWalk,
    )

    own = {**(config or {}), "step_length": step, "robot_radius": sim.config.robot_radius,
           "lidar_range": sim.config.lidar_range}
    if method == "frontier":
        return FrontierExplorer(FrontierConfig(**own))
    if method == "frontier_paper":
        return FrontierPaperExplorer(FrontierPaperConfig(**own))
    if method == "nbv":
        return NextBestView(NBVConfig(**own))
    if method == "random":
        return RandomWalk(step, seed=seed)
    if method == "oracle":
        return OracleTour(OracleConfig(**{k: v for k, v in own.items() if k in OracleConfig.__dataclass_fields__}))
    raise ValueError(f"unknown method {method!r}")


def explore_episode(env: str, method: str, seed: int, steps: int, noise=None, patience: int | None = None,
                    config: dict | None = None, faults=(), end: dict | None = None, end_rule: str | None = None,
                    on_step=None):
    """Run one method in a fresh simulator until its own end or the budget (the study's stop rule,
    ``config.STOP_RULE``); returns (sim, episode, agent-or-policy, ended_by_itself). Caller closes sim.
    ``config`` overrides fields of the method's config: the baseline's dataclass, or AIMAPP's
    ``aimapp_config(method, env)`` (e.g. ``{"view_bounds": ...}``; the studies pass none for AIMAPP).
    ``end_rule`` is AIMAPP's (:class:`cogmap.explore.Done`; default ``config.AIMAPP_END_RULE``).
    ``end``, if given, receives ``end_reason`` and (AIMAPP) ``unvisited_reachable`` (:meth:`Done.summary`).
    ``on_step``, if given (AIMAPP only), is called as ``on_step(sim, agent)`` after each planning call,
    before the move: a read-only look at the run (e.g. ``bench/gain_audit.py``)."""
    from cogmap.agent.aimapp import AIMAPPAgent
    from cogmap.baselines import run_policy
    from cogmap.explore import Done, default_config, run_agent

    from .config import AIMAPP_END_RULE, AIMAPP_PATIENCE, aimapp_config

    if on_step is not None and not method.startswith("aimapp"):
        raise ValueError(f"explore_episode: on_step is for AIMAPP runs, not {method!r}")
    if method.startswith("aimapp"):  # before the simulator opens: a bad override leaves nothing open
        agent_cfg = replace(aimapp_config(method, env), **(config or {}))
    cfg = default_config(env)
    sim = study_sim(env, cfg, seed, noise)
    for stream, start, length in faults:  # (stream, first silent step, number of silent steps)
        sim.inject_fault(stream, start, length)
    if method.startswith("aimapp"):
        agent = AIMAPPAgent(agent_cfg, seed=seed)
        done = Done(agent, AIMAPP_PATIENCE if patience is None else patience,  # the agent's own end
                    end_rule or AIMAPP_END_RULE)
        watch = None if on_step is None else (lambda _decision: on_step(sim, agent))
        ep = run_agent(sim, agent, steps, progress=False, on_step=watch, stop=done)
        if end is not None:
            end.update({k: v for k, v in done.summary().items() if k != "ended_by_agent"})
        return sim, ep, agent, done.finished
    pol = make_policy(method, sim, cfg.influence_radius, seed, config)
    ep = run_policy(sim, pol, steps)
    ended = bool(ep.rows and ep.rows[-1]["mode"] == "done")
    if end is not None:
        end.update({"end_reason": BASELINE_END.get(method, "own end") if ended else Done.BUDGET,
                    "unvisited_reachable": None})
    return sim, ep, pol, ended


#: how a baseline declares itself finished (its ``mode == "done"``)
BASELINE_END = {"frontier": "no frontier left", "frontier_paper": "no frontier left",
                "nbv": "no viewpoint worth a detour", "oracle": "no viewpoint worth a detour"}


def exploration_result(spec, sim, ep, ended_by_itself: bool = False, end: dict | None = None) -> dict:
    """Both endpoints (90 % coverage and end of run), interventions and success, drift, digest."""
    from cogmap.explore import default_config, episode_metrics

    m = episode_metrics(sim, ep)
    rule = SuccessRule(**spec["success_rule"])
    mismatch_m = rule.mismatch_m if rule.mismatch_m is not None else default_config(spec["env"]).influence_radius
    budget = nauc_budget(m["free_area_m2"])
    truth = [[r["true_x"], r["true_y"]] for r in ep.rows]
    odom = [[r["odom_x"], r["odom_y"]] for r in ep.rows]
    belief = [[r["belief_x"], r["belief_y"]] for r in ep.rows]
    moved = [r["moved"] for r in ep.rows]
    events = interventions(truth, moved, belief, rule, mismatch_m)
    ends = endpoints(ep.distance, ep.coverage, m["free_area_m2"], budget, spec["coverage_level"])
    out = {
        "coverage": m["coverage"], "area_covered_m2": m["area_covered_m2"], "free_area_m2": m["free_area_m2"],
        "distance_m": m["distance_m"], "steps": m["steps"], "ce": ends["end"]["ce"], "nauc": ends["end"]["nauc"],
        "nauc_budget_m": budget, "nauc_own_distance": m["nauc"],
        "at_level": ends["at_level"], "level_step": ends["level_index"], "ended_by_itself": ended_by_itself,
        **(end or {}),
        "failed_moves": m["failed_moves"], "silent_decisions": sum(1 for r in ep.rows if r.get("missing")),
        "interventions": events, "mismatch_m": mismatch_m,
        "success": not events,
        "num_states": m["num_states"], "num_observations": m["num_observations"],
        "decision_mean_ms": m["decision_ms_mean"], "decision_p95_ms": m["decision_ms_p95"],
        **(drift_metrics(truth, odom, belief) if ep.rows else {}),
        **_identity(sim, ep),
        "curve": _curve(ep),
    }
    return out


def _identity(sim, ep) -> dict:
    """Start pose and digest of the true trajectory (to prove that no run appears twice)."""
    path = [[r["true_x"], r["true_y"]] for r in ep.rows] + [sim.true_pose()[:2].tolist()]
    return {"start_pose": [round(float(v), 4) for v in sim.path[0]], "trajectory_digest": trajectory_digest(path)}


def _explore(spec):
    """The exploration run of ``spec``: (sim, episode, agent-or-policy, ended_by_itself, end)."""
    opts = spec["method_options"]
    # AIMAPP runs with aimapp_config(method, env), which is what its spec records; a baseline's recorded config
    config = opts.get("config") if not spec["method"].startswith("aimapp") else None
    end: dict = {}
    sim, ep, agent, ended = explore_episode(spec["env"], spec["method"], spec["seed"], spec["steps"], _noise(spec),
                                            opts.get("patience"), config, _faults(spec), end, opts.get("end_rule"))
    return sim, ep, agent, ended, end


def run_exploration(spec) -> dict:
    """Both endpoints of one exploration run; with ``spec["goals"]`` (the generalisation study's
    AIMAPP runs) also the goal runs that follow it (:func:`goal_runs`)."""
    sim, ep, agent, ended, end = _explore(spec)
    try:
        out = exploration_result(spec, sim, ep, ended, end)
    finally:
        sim.close()
    if spec.get("goals"):
        out["goals"] = goal_runs(spec, agent, spec["goals"])
    return out


def run_drift(spec) -> dict:
    """One exploration run of a level (odometry noise: drift and slip studies; silent stream:
    dropout study), without its coverage curve."""
    out = run_exploration(spec)
    out.pop("curve", None)
    out["level"] = spec["level"]
    return out


def _choose_goals(agent, start_state: int, k: int, min_dist: float) -> list[tuple[int, list[int]]]:
    """Up to ``k`` stored observations whose states lie farthest (stored pose) from the start."""
    poses = agent.poses
    cands = []
    saved = agent.goal_obs
    for o in range(agent.model.num_obs[0]):
        agent.set_goal(o)
        gs = [int(s) for s in np.atleast_1d(agent.goal_states())]
        if not gs or start_state in gs:
            continue
        d = float(np.min(np.hypot(*(poses[gs] - poses[start_state]).T)))
        if d >= min_dist:
            cands.append((d, o, gs))
    agent.set_goal(saved)
    cands.sort(key=lambda t: (-t[0], t[1]))
    return [(o, gs) for _, o, gs in cands[:k]]


def goal_runs(spec, agent, params: dict) -> list[dict]:
    """From the exploration start (known, as in the paper's protocol), pursue the stored views
    farthest from it (``params``: ``goals_per_run``, ``goal_steps``, ``min_goal_distance``), each with
    a copy of the explored ``agent`` in a fresh simulator; one result per goal."""
    from cogmap.explore import default_config
    from cogmap.goal import pursue

    cfg = default_config(spec["env"])
    base = copy.deepcopy(agent)
    sim = study_sim(spec["env"], cfg, spec["seed"])
    try:
        start_state = base.localise_at(sim.odometry())
        goals = _choose_goals(base, start_state, params["goals_per_run"], params["min_goal_distance"])
    finally:
        sim.close()
    results = []
    for gi, (obs, goal_states) in enumerate(goals):
        ag = copy.deepcopy(base)
        ag.rng = np.random.default_rng([spec["seed"], gi])
        sim = study_sim(spec["env"], cfg, spec["seed"])
        try:
            s0 = ag.localise_at(sim.odometry())
            plan_m = graph_plan_length(ag.model.B[0], ag.poses, s0, goal_states, cfg.inductive_threshold)
            gep, summary = pursue(sim, ag, obs, params["goal_steps"], progress=False)
            res = {"goal": gi, "goal_obs": obs, "goal_states": goal_states, "reached": summary["reached"],
                   "steps": summary["steps"], "executed_m": summary["executed_m"], "astar_m": summary["astar_m"],
                   "plan_m": plan_m,
                   **path_length_ratios(summary["executed_m"], summary["astar_m"], plan_m)}
            results.append(res)
        finally:
            sim.close()
    return results


def run_goals(spec) -> dict:
    """Explore, then from the exploration start (known) pursue stored goal observations."""
    sim, ep, agent, _ = explore_episode(spec["env"], "aimapp", spec["seed"], spec["steps"], None,
                                        spec["method_options"].get("patience"))
    explore_cov = float(ep.coverage[-1])
    ident = _identity(sim, ep)
    sim.close()
    results = goal_runs(spec, agent, spec["params"])
    return {"explore_steps": len(ep.rows), "explore_coverage": explore_cov, "num_states": agent.num_states,
            "num_observations": int(agent.model.num_obs[0]), "goals": results, **ident}


def run_obstacle(spec) -> dict:
    """Figure 8: explore, move a box onto a free node the agent knows, track the belief of
    transitions into that node."""
    from cogmap.explore import run_agent

    p = spec["params"]
    agent, sim = study_agent(spec)
    try:
        trace = []

        def record(phase):
            B = agent.model.B[0]
            n = agent.num_states
            t = transitions_into(B.succ, B.prob, node, n) if node is not None else None
            trace.append({"step": sim.step_count, "phase": phase, **(t or {})})

        node = None
        ep = run_agent(sim, agent, spec["steps"], progress=False)
        box = sim.layout.shape(p["box"])
        half = max(getattr(box, "sx", 0.0), getattr(box, "sy", 0.0)) / 2
        robot = sim.true_pose()[:2]
        B = agent.model.B[0]
        n = agent.num_states
        best = None
        for s in range(n):
            xy = agent.poses[s]
            if np.hypot(*(xy - robot)) < half + sim.config.robot_radius + 0.6:
                continue
            if np.hypot(xy[0] - box.x, xy[1] - box.y) < 2 * half + 0.3:  # must be a new place
                continue
            if not _box_fits(sim, p["box"], xy):
                continue
            incoming = transitions_into(B.succ, B.prob, s, n)["above_half"]
            if best is None or incoming > best[0]:
                best = (incoming, s)
        if best is None:
            return {"node": None, "trace": [], "note": "no free node to block", **_identity(sim, ep)}
        node = best[1]
        target = agent.poses[node].copy()
        record("before")
        sim.schedule_obstacle_move(p["box"], target, at_step=sim.step_count + 1)
        for _ in range(p["after_steps"]):
            run_agent(sim, agent, 1, progress=False, episode=ep)
            record("after")
        return {"node": int(node), "node_pose": target.tolist(), "moved_at_step": trace[0]["step"] + 1,
                "trace": trace, "failed_moves": int(sum(1 for r in ep.rows if r["moved"] is False)),
                **_identity(sim, ep)}
    finally:
        sim.close()


def _box_fits(sim, name, xy) -> bool:
    """The box moved to ``xy`` overlaps no other shape and stays inside the room."""
    from cogmap.envs.geometry import ShapeSet

    moved = sim.layout.with_moved(name, xy)
    box = moved.shape(name)
    others = ShapeSet([s for s in moved.shapes if s.name != name])
    hx, hy = box.sx / 2, box.sy / 2
    pts = np.array([[box.x + a * hx, box.y + b * hy] for a in (-1, 0, 1) for b in (-1, 0, 1)])
    xmin, ymin, xmax, ymax = moved.bounds
    inside = (pts[:, 0] > xmin) & (pts[:, 0] < xmax) & (pts[:, 1] > ymin) & (pts[:, 1] < ymax)
    return bool(inside.all() and np.all(others.distance(pts) > 0.05))


def model_size_bytes(model) -> int:
    from cogmap.genmodel.io import save

    with tempfile.TemporaryDirectory() as tmp:
        paths = save(model, Path(tmp) / "model")
        return int(sum(Path(q).stat().st_size for q in paths))


def run_scaling(spec) -> dict:
    """Figure 13: time per decision against the number of states; model size against the
    number of stored observations."""
    from cogmap.explore import run_agent

    every = spec["params"]["size_every"]
    agent, sim = study_agent(spec)
    try:
        sizes = []

        def on_step(_d):
            if agent.counts.steps % every == 0:
                sizes.append({"step": agent.counts.steps, "num_states": agent.num_states,
                              "num_observations": int(agent.model.num_obs[0]),
                              "model_bytes": model_size_bytes(agent.model)})

        ep = run_agent(sim, agent, spec["steps"], progress=False, on_step=on_step)
        sizes.append({"step": agent.counts.steps, "num_states": agent.num_states,
                      "num_observations": int(agent.model.num_obs[0]), "model_bytes": model_size_bytes(agent.model)})
        return {"num_states": [int(v) for v in ep.num_states], "decision_ms": [round(v, 3) for v in ep.decision_ms],
                "sizes": sizes, "coverage": float(ep.coverage[-1]), **_identity(sim, ep)}
    finally:
        sim.close()


_DIGEST: str | None = None


def code_digest() -> str:
    """SHA-256 (16 hex) of every Python source of the installed packages (cogmap, genmodel,
    inference, planning, envs) as on disk at this process's first run: runs made while someone edits
    the tree carry different digests, and the report says so."""
    global _DIGEST
    if _DIGEST is None:
        import hashlib

        import cogmap
        from cogmap import envs, genmodel, inference, planning

        h = hashlib.sha256()
        for package in (cogmap, genmodel, inference, planning, envs):
            root = Path(package.__file__).parent
            files = sorted(root.glob("*.py")) if package is not cogmap else sorted(root.rglob("*.py"))
            for f in files:
                h.update(str(f.relative_to(root)).encode())
                h.update(f.read_bytes())
        _DIGEST = h.hexdigest()[:16]
    return _DIGEST


def strip_timings(x):
    """The deterministic part of a result (timing fields removed) for comparisons."""
    if isinstance(x, dict):
        return {k: strip_timings(v) for k, v in x.items() if not k.endswith(TIMING_SUFFIXES) and k != "decision_ms"}
    if isinstance(x, list):
        return [strip_timings(v) for v in x]
    return x

"""Cost of the AIMAPP agent as its map grows: 500, 2,000, 10,000 and 20,000 states.

For each size, in a fresh process (so peak memory is that size's own):

1. a synthetic map is built through the public growth and learning calls (``add_state``,
   ``add_observation``, ``learn_transition``, ``learn_observation``): states on a 1 m lattice,
   4-connected (about 3.8 learned moves per state), half the places visited and tied to an
   observation of their own;
2. the real agent steps in a numpy box world of the same size (exact odometry, the encoder names
   the 1 m cell), starting mid-map: time per agent step (sense -> infer -> learn -> plan) and per
   planning decision (MCTS, 30 simulations, depth 10, exploration objective), median and p95;
   then half as many steps in goal mode (preferences and the inductive term, whose reachability
   search runs over the whole map);
3. on the grown model: amortised time of ``add_observation``, ``add_state`` (1,000 each), of one
   A_o update (a view tied to a random place) and one B_s update, and the reallocations the
   2,000 growth steps performed;
4. peak resident memory of the process.

The 500-state figures are the reference column (ratios beside the others). A last section times
policy evaluation on small dense models (25 states, policies of length 2, and larger) against
pymdp 1.0 in the same process.

    python bench/scale.py [--sizes 500 2000 10000 20000] [--steps 60] [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import multiprocessing as mp
import resource
import sys
import time

import numpy as np


def lattice_agent(n: int, seed: int = 0):
    """An agent whose model holds ``n`` states on a 1 m lattice (see module docstring)."""
    from cogmap.agent.aimapp import AIMAPPAgent, initial_model
    from cogmap.agent.config import AgentConfig
    from cogmap.agent.testing import CellEncoder
    from cogmap.inference.learning import Event, learn_observation, learn_transition

    rng = np.random.default_rng(seed)
    cfg = AgentConfig(influence_radius=1.0, initial_capacity=64)
    side = int(np.ceil(np.sqrt(n)))
    cells = [(i % side, i // side) for i in range(n)]
    poses = np.asarray(cells, dtype=float) + 0.5
    model = initial_model(cfg, poses[0])
    for i in range(1, n):
        model.add_state(0, pose=poses[i], obs_count=cfg.prior_count / model.num_obs[0])
    index = {c: i for i, c in enumerate(cells)}
    for (x, y), s in index.items():
        for h, (dx, dy) in ((0, (1, 0)), (3, (0, 1)), (6, (-1, 0)), (9, (0, -1))):
            t = index.get((x + dx, y + dy))
            if t is not None:
                learn_transition(model, 0, s, h, t, Event.POSSIBLE, reverse_control=(h + 6) % 12, rates=cfg.learning)
    encoder = CellEncoder(1.0)
    visited = np.flatnonzero(rng.random(n) < 0.5)
    onehot = np.zeros(n)
    for s in visited:
        o = len(encoder.ids)
        encoder.ids[cells[s]] = o
        if o >= model.num_obs[0]:
            model.add_observation(0)
        onehot[s] = 1.0
        learn_observation(model, 0, o, [onehot], lr=cfg.obs_learning_rate)
        onehot[s] = 0.0
    start = index[(side // 2, side // 2)] if (side // 2, side // 2) in index else n // 2
    agent = AIMAPPAgent(cfg, encoder=encoder, seed=seed, model=model)
    q = np.zeros(n)
    q[start] = 1.0
    agent.belief = agent.belief._replace(q=q)
    return agent, poses[start], side


def measure(n: int, steps: int, seed: int = 0) -> dict:
    """All figures for one size (runs in its own process)."""
    from cogmap.agent import planner
    from cogmap.agent.testing import BoxWorld
    from cogmap.inference.learning import Event, learn_observation, learn_transition

    t0 = time.perf_counter()
    agent, start, side = lattice_agent(n, seed)
    build_s = time.perf_counter() - t0
    world = BoxWorld(float(side), float(side), start=start)
    plan_ms: list[float] = []
    decide = planner.decide

    def timed(*args, **kwargs):
        t = time.perf_counter()
        out = decide(*args, **kwargs)
        plan_ms.append(1e3 * (time.perf_counter() - t))
        return out

    planner.decide = timed
    step_ms, moved = [], None
    try:
        for _ in range(steps):
            sensed = world.sense(moved)
            t = time.perf_counter()
            d = agent.step(sensed)
            step_ms.append(1e3 * (time.perf_counter() - t))
            moved = world.act(d, agent.cfg.stay)
        explore_ms = plan_ms[1:]
        plan_ms.clear()
        agent.set_goal(0)  # goal mode: preferences, inductive term over the whole map
        for _ in range(steps // 2):
            d = agent.step(world.sense(moved))
            moved = world.act(d, agent.cfg.stay)
        goal_ms = plan_ms[1:]
    finally:
        planner.decide = decide
    model, cfg = agent.model, agent.cfg
    grown = model.num_states[0]

    def per_call(fn, k: int, warm: bool = True) -> float:
        for i in range(k // 10 if warm else 0):  # warm-up: first touches of freshly allocated memory
            fn(i)
        t = time.perf_counter()
        for i in range(k):
            fn(i)
        return 1e3 * (time.perf_counter() - t) / k

    rng = np.random.default_rng(1)
    places = rng.integers(grown, size=200)
    views = rng.integers(model.num_obs[0], size=200)
    onehot = np.eye(1, grown + 2000, 0)[0]

    def learn_view(i):  # a confident visit ties a view to a place (one-hot belief)
        onehot[:] = 0.0
        onehot[places[i]] = 1.0
        learn_observation(model, 0, int(views[i]), [onehot], lr=cfg.obs_learning_rate)

    learn_a = per_call(learn_view, 200)
    learn_b = per_call(lambda i: learn_transition(model, 0, grown // 2, i % 12, grown // 2 + 1, Event.POSSIBLE,
                                                  reverse_control=(i % 12 + 6) % 12, rates=cfg.learning), 200)
    before = model.compile_count + model.A[0].reallocations
    add_obs = per_call(lambda i: model.add_observation(0), 1000, warm=False)
    add_state = per_call(lambda i: model.add_state(0, pose=(-1.0 - i, -1.0), obs_count=0.1 / model.num_obs[0]), 1000,
                         warm=False)
    reallocs = model.compile_count + model.A[0].reallocations - before
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    pct = lambda x, p: float(np.percentile(x, p))  # noqa: E731
    return {
        "states": n, "states_after_run": grown, "build_s": build_s,
        "step_ms_median": pct(step_ms[1:], 50), "step_ms_p95": pct(step_ms[1:], 95),
        "decision_ms_median": pct(explore_ms, 50), "decision_ms_p95": pct(explore_ms, 95),
        "goal_decision_ms_median": pct(goal_ms, 50), "goal_decision_ms_p95": pct(goal_ms, 95),
        "learn_A_ms": learn_a, "learn_B_ms": learn_b,
        "add_observation_ms": add_obs, "add_state_ms": add_state, "reallocations_per_2000_growths": reallocs,
        "peak_rss_mb": peak_mb,
    }


def _child(n, steps, seed, out):
    out.put(measure(n, steps, seed))


def in_fresh_process(n: int, steps: int, seed: int = 0) -> dict:
    ctx = mp.get_context("spawn")
    out = ctx.Queue()
    p = ctx.Process(target=_child, args=(n, steps, seed, out))
    p.start()
    result = out.get()
    p.join()
    return result


def _dense_case(n: int, o: int = 8, u: int = 4):
    rng = np.random.default_rng(n)
    A = rng.gamma(0.7, size=(o, n)) + 1e-3
    A /= A.sum(0)
    B = rng.gamma(0.5, size=(n, n, u)) + 1e-3
    B /= B.sum(0)
    return dict(A=A, B=B, C=rng.normal(size=o), pA=A * 5 + 0.5, pB=B * 5 + 0.5, qs=rng.dirichlet(np.ones(n)))


def _median_ms(fn, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return 1e3 * float(np.median(times))


def policy_evaluation(sizes=((25, 2), (100, 2), (400, 2), (25, 3)), repeats: int = 30) -> list[dict]:
    """Dense policy evaluation (utility + state and parameter information gain), ours against
    pymdp 1.0's ``update_posterior_policies`` compiled with ``jax.jit`` (first call excluded)."""
    import jax
    import jax.numpy as jnp
    from pymdp import control

    from cogmap.planning import efe
    from cogmap.planning.arrays import PlanningArrays
    from cogmap.planning.policies import enumerate_policies, evaluate_policies

    jax.config.update("jax_enable_x64", True)
    obj = efe.pymdp_like(use_param_info_gain=True)

    @jax.jit
    def pymdp_neg_efe(policies, qs, A, B, C, E, pA, pB):
        _, neg = control.update_posterior_policies(policies, qs, A, B, C, E, pA, pB, [[0]], [[0]], gamma=1.0,
                                                   use_utility=True, use_states_info_gain=True,
                                                   use_param_info_gain=True)
        return neg

    rows = []
    for n, length in sizes:
        m = _dense_case(n)
        o, u = m["A"].shape[0], m["B"].shape[2]
        arrays = PlanningArrays(A=[m["A"]], A_deps=((0,),), B=[m["B"]], C=[m["C"]], num_states=(n,),
                                num_obs=(o,), num_controls=(u,), pA=[m["pA"]], pB=[m["pB"]])
        policies = enumerate_policies((u,), length)
        j = {k: [jnp.asarray(v)] for k, v in m.items()}
        jargs = (jnp.asarray(policies), j["qs"], j["A"], j["B"], j["C"], jnp.ones(len(policies)) / len(policies),
                 j["pA"], j["pB"])
        ours = evaluate_policies(arrays, [m["qs"]], policies, obj)
        theirs = np.asarray(pymdp_neg_efe(*jargs))  # also compiles
        np.testing.assert_allclose(-ours, theirs, rtol=1e-8, atol=1e-8)  # the same quantity
        a = _median_ms(lambda a=arrays, m=m, p=policies: evaluate_policies(a, [m["qs"]], p, obj), repeats)
        b = _median_ms(lambda args=jargs: pymdp_neg_efe(*args).block_until_ready(), repeats)
        rows.append({"states": n, "policy_length": length, "policies": len(policies), "ours_ms": a,
                     "pymdp_ms": b, "speedup": b / a})
    return rows


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[500, 2000, 10000, 20000])
    ap.add_argument("--steps", type=int, default=60, help="agent steps per size")
    ap.add_argument("--json", help="also write the figures to this JSON file")
    ap.add_argument("--no-pymdp", action="store_true", help="skip the policy-evaluation comparison")
    args = ap.parse_args(argv)
    results = []
    for n in args.sizes:
        t = time.perf_counter()
        results.append(in_fresh_process(n, args.steps))
        print(f"  {n} states measured in {time.perf_counter() - t:.0f} s", file=sys.stderr)
    ref = results[0]
    cols = [("step_ms_median", "step ms (median)"), ("step_ms_p95", "step ms (p95)"),
            ("decision_ms_median", "decision ms (median)"), ("decision_ms_p95", "decision ms (p95)"),
            ("goal_decision_ms_median", "goal decision ms (median)"),
            ("goal_decision_ms_p95", "goal decision ms (p95)"),
            ("learn_A_ms", "A_o update ms"), ("learn_B_ms", "B_s update ms"),
            ("add_observation_ms", "add_observation ms"), ("add_state_ms", "add_state ms"),
            ("reallocations_per_2000_growths", "reallocations / 2,000 growths"), ("peak_rss_mb", "peak RSS MB")]
    print(f"\nAIMAPP agent on a synthetic lattice map, {args.steps} steps per size "
          f"(ratio to the {ref['states']}-state column in brackets)")
    print(f"{'':32}" + "".join(f"{r['states']:>18,}" for r in results))
    for key, label in cols:
        cells = []
        for r in results:
            v = r[key]
            ratio = "" if r is ref or not ref[key] else f" ({v / ref[key]:.2f}x)"
            cells.append(f"{v:.3f}{ratio}" if isinstance(v, float) else f"{v}{ratio}")
        print(f"{label:32}" + "".join(f"{c:>18}" for c in cells))
    report = {"agent": results}
    if not args.no_pymdp:
        rows = policy_evaluation()
        report["policy_evaluation"] = rows
        print("\npolicy evaluation (utility + state and parameter information gain), dense, same process")
        print(f"{'states':>7} {'length':>7} {'policies':>9} {'ours ms':>9} {'pymdp ms':>9} {'speed-up':>9}")
        for r in rows:
            print(f"{r['states']:>7} {r['policy_length']:>7} {r['policies']:>9} {r['ours_ms']:>9.3f} "
                  f"{r['pymdp_ms']:>9.3f} {r['speedup']:>8.2f}x")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(report, fh, indent=1)
        print(f"\nwritten {args.json}")


if __name__ == "__main__":
    main()

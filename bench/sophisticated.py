"""Time sophisticated inference (planner ``"sophisticated"``): one decision at 400 states, horizon 4.

Decisions are taken at the beliefs an agent loop meets on a 20 x 20 grid (``grid_model``: a
location sensor right 80 % of the time; ``landmark_grid_model``: the start unknown within the
first column, exact landmarks on the middle row), with pymdp's objective (utility + state
information gain), ``gamma = 16`` and SPM's pruning (1/16 on outcomes and controls, at most 16
outcomes per control). The exhaustive recursion (no pruning) is timed beside the pruned one on
small models. Run::

    python bench/sophisticated.py [--decisions 8] [--horizon 4] [--json out.json]
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # small arrays per node: threads only cost

import argparse  # noqa: E402
import json  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from cogmap import loop  # noqa: E402
from cogmap.envs.jax_worlds import grid_model, landmark_grid_model, tmaze_model  # noqa: E402
from cogmap.planning import efe, sophisticated_efe  # noqa: E402
from cogmap.planning.sophisticated import EXHAUSTIVE  # noqa: E402


def beliefs_along_a_walk(model, decisions: int, horizon: int) -> list:
    """The posteriors of the loop (planner "sophisticated") walking the grid, the true cell observed."""
    B = model.live_B(0)
    side = int(round(np.sqrt(model.num_states[0])))
    cell = side * (side // 4)  # first column, a quarter of the way up
    state = loop.init(model, planner="sophisticated", policy_len=horizon, sample=False)
    out = []
    for _ in range(decisions):
        state, info = loop.step(state, [cell])
        out.append([q.copy() for q in info.qs])
        cell = int(np.argmax(B[:, cell, info.action[0]]))
    return out


def time_one(model, qs, horizon, config=None, repeats: int = 3):
    """Fastest of ``repeats`` wall-clock times (s) of one decision, and its search info."""
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        G, info = sophisticated_efe(model, qs, efe.pymdp_like(), horizon, 16.0, config)
        best = min(best, time.perf_counter() - t0)
    return best, G, info


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--decisions", type=int, default=8, help="decisions timed per model")
    ap.add_argument("--horizon", type=int, default=4)
    ap.add_argument("--json", help="also write the figures to this JSON file")
    args = ap.parse_args()
    report: dict = {"horizon": args.horizon, "large": {}, "small": {}}

    print(f"one decision, pruned (SPM thresholds), horizon {args.horizon}, 400 states, "
          f"median over {args.decisions} decisions of a walk")
    print(f"{'model':<22}{'median ms':>10}{'max ms':>9}{'nodes (median)':>16}{'reused':>8}")
    for name, model in (("grid_model(20)", grid_model(side=20)), ("landmark_grid_model(20)",
                                                                   landmark_grid_model(side=20))):
        times, nodes, reused = [], [], []
        for qs in beliefs_along_a_walk(model, args.decisions, args.horizon):
            t, _, info = time_one(model, qs, args.horizon)
            times.append(t)
            nodes.append(info.nodes)
            reused.append(info.reused)
        med, mx = 1e3 * float(np.median(times)), 1e3 * float(np.max(times))
        print(f"{name:<22}{med:>10.1f}{mx:>9.1f}{int(np.median(nodes)):>16d}{int(np.median(reused)):>8d}")
        report["large"][name] = {"median_ms": med, "max_ms": mx, "nodes": nodes, "reused": reused}

    print("\nexhaustive recursion (thresholds 0, every outcome) beside the pruned one, small models")
    print(f"{'model':<28}{'horizon':>8}{'exhaustive ms':>15}{'nodes':>8}{'pruned ms':>11}{'nodes':>7}"
          f"{'max |dG|':>10}{'same choice':>13}")
    tm, g3, l3 = tmaze_model(), grid_model(side=3), landmark_grid_model(side=3)
    tq = [np.eye(4)[0], np.array([0.5, 0.5])]
    small = [("tmaze", tm, tq, 3), ("tmaze", tm, tq, 4),
             ("grid_model(3), q uniform", g3, [np.full(9, 1 / 9)], 3),
             ("landmark_grid_model(3)", l3, [l3.live_D(0)], 3)]
    for name, model, qs, h in small:
        te, Ge, ie = time_one(model, qs, h, EXHAUSTIVE, repeats=1)
        tp, Gp, ip = time_one(model, qs, h)
        same = bool(Ge[int(np.argmin(Gp))] <= Ge.min() + 1e-9)  # ties: any minimiser
        dG = float(np.abs(Ge - Gp)[ip.expanded].max())  # the controls the pruned search expanded
        print(f"{name:<28}{h:>8d}{1e3 * te:>15.1f}{ie.nodes:>8d}{1e3 * tp:>11.1f}{ip.nodes:>7d}{dG:>10.3g}"
              f"{str(same):>13}")
        report["small"][name] = {"horizon": h, "exhaustive_ms": 1e3 * te, "exhaustive_nodes": ie.nodes,
                                 "pruned_ms": 1e3 * tp, "pruned_nodes": ip.nodes, "max_abs_dG": dG,
                                 "same_choice": same}
    print("(max |dG| over the root controls the pruned search expanded; the others get 512/gamma above the best)")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(report, fh, indent=1)
        print(f"\nwritten {args.json}")


if __name__ == "__main__":
    main()

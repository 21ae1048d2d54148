"""Coverage efficiency of AIMAPP against the oracle tour, per layout, at 90 % coverage.

For every layout (5 seeds, decision budgets of ``cogmap.study.config.STEPS_FULL``) one AIMAPP
run (ending by itself, as in the studies) and one oracle tour (``cogmap.baselines.OracleTour``)
from the same start. CE@90 = area covered / distance travelled, both read at the first decision
where the LiDAR coverage reaches 90 % (``coverage`` and ``distance`` lists of the episode); a run
that never reaches 90 % has no CE@90, nor has one whose first scan already covers 90 % (distance 0;
the bedroom from seeds 0 and 3). The ratio is AIMAPP / oracle of the per-layout means.

With ``--outline`` the explorers are told the layout's outline (``Layout.bounds``: AIMAPP's
``view_bounds``, the next-best-view explorer's ``bounds``), so their imagined views count nothing
outside the building: how much of the gap to the oracle is not knowing where the building ends.

    python bench/exploration.py [--envs house bedroom] [--seeds 0 1 2 3 4] [--methods aimapp nbv oracle]
                                [--outline] [--figure docs/img/efe-terms.png]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from cogmap.study.config import ALL_ENVS, STEPS_FULL

THRESHOLD = 0.9


def ce_at(coverage, distance, free_area: float, threshold: float = THRESHOLD) -> float | None:
    """Area covered / distance at the first index where ``coverage >= threshold`` (None if never)."""
    c = np.asarray(coverage, dtype=float)
    hit = np.flatnonzero(c >= threshold)
    if hit.size == 0:
        return None
    i = int(hit[0])
    d = float(distance[i])
    return float(c[i] * free_area / d) if d > 0 else None


#: the config field through which each explorer is told the outline (``--outline``)
OUTLINE_FIELD = {"aimapp": "view_bounds", "nbv": "bounds"}


def run(env: str, method: str, seed: int, steps: int, outline: bool = False) -> dict:
    from cogmap.envs.layouts import LAYOUTS
    from cogmap.explore import coverage_tracker
    from cogmap.study.runs import explore_episode

    config = {OUTLINE_FIELD[method]: LAYOUTS[env]().bounds} if outline and method in OUTLINE_FIELD else None
    sim, ep, _, _ = explore_episode(env, method, seed, steps, config=config)  # the studies' run end
    try:
        tracker = coverage_tracker(sim)
        free = tracker.total * sim.grid.resolution**2
        return {"ce90": ce_at(ep.coverage, ep.distance, free), "coverage": ep.coverage[-1],
                "distance": ep.distance[-1], "steps": len(ep.rows),
                "ms": float(np.mean(ep.decision_ms)) if ep.decision_ms else 0.0}
    finally:
        sim.close()


def _mean(values) -> str:
    v = [x for x in values if x is not None]
    return f"{np.mean(v):.2f} ± {np.std(v):.2f}" if v else "–"


def table(results: dict, envs, seeds, methods=("aimapp",)) -> str:
    """One row per layout and explorer (every method but the oracle) against the oracle's runs."""
    lines = ["| layout | method | CE@90 | oracle CE@90 | ratio | runs with CE@90 | final coverage "
             "| oracle final coverage | distance (m) | ms/decision |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for env in envs:
        o = [results[(env, "oracle", s)] for s in seeds]
        co = [r["ce90"] for r in o if r["ce90"] is not None]
        for method in methods:
            a = [results[(env, method, s)] for s in seeds]
            ca = [r["ce90"] for r in a if r["ce90"] is not None]
            ratio = f"{np.mean(ca) / np.mean(co):.2f}" if ca and co else "–"
            lines.append(f"| {env} | {method} | {_mean(ca)} | {_mean(co)} | {ratio} | {len(ca)}/{len(a)} "
                         f"| {_mean([r['coverage'] for r in a])} | {_mean([r['coverage'] for r in o])} "
                         f"| {_mean([r['distance'] for r in a])} | {np.mean([r['ms'] for r in a]):.1f} |")
    return "\n".join(lines)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--envs", nargs="*", default=list(ALL_ENVS))
    ap.add_argument("--seeds", nargs="*", type=int, default=[0, 1, 2, 3, 4])
    ap.add_argument("--methods", nargs="*", default=["aimapp", "oracle"])
    ap.add_argument("--outline", action="store_true",
                    help="tell AIMAPP and the next-best-view explorer the layout's outline (Layout.bounds)")
    ap.add_argument("--figure", default=None, help="also draw the per-decision EFE terms of a house run to this PNG")
    args = ap.parse_args(argv)
    if args.figure:
        import sys
        from pathlib import Path

        sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "docs"))
        from efe_terms import draw  # the figure script of docs/exploration.md

        draw(args.figure)
        return
    results = {}
    t0 = time.perf_counter()
    for env in args.envs:
        for method in args.methods:
            for seed in args.seeds:
                r = run(env, method, seed, STEPS_FULL[env], args.outline)
                results[(env, method, seed)] = r
                ce = "–" if r["ce90"] is None else f"{r['ce90']:.2f}"
                print(f"{env:16s} {method:7s} seed {seed}: CE@90 {ce:>5s}  final coverage {r['coverage']:.3f}  "
                      f"distance {r['distance']:6.1f} m  steps {r['steps']}", flush=True)
    explorers = [m for m in args.methods if m != "oracle"]
    if "oracle" in args.methods and explorers:
        print()
        print(table(results, args.envs, args.seeds, explorers))
    print(f"\n{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()

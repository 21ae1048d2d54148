"""Time per AIMAPP decision (infer + learn + plan) against the number of states.

A long exploration of a 60 m x 60 m empty room (the numpy box world of
``cogmap.agent.testing``): odometry exact and an encoder that names the 1 m cell the robot
stands in (every place looks different), so the map keeps growing and the cost of one decision
can be read at 50 ... 2,000 states without any simulator time mixed in.
Also prints, for reference, the same agent in the pybullet mini warehouse.

    python bench/agent.py [--steps 2500]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from cogmap.agent.aimapp import AIMAPPAgent
from cogmap.agent.config import AgentConfig
from cogmap.agent.testing import BoxWorld, CellEncoder


def open_plane(steps: int, seed: int = 0):
    """(states, ms) per decision in a 60 m x 60 m empty box world."""
    cfg = AgentConfig(influence_radius=1.0, initial_capacity=64)
    world = BoxWorld(60.0, 60.0, start=(30.0, 30.0))
    agent = AIMAPPAgent(cfg, encoder=CellEncoder(1.0), seed=seed)
    samples, moved = [], None
    for _ in range(steps):
        sensed = world.sense(moved)
        t0 = time.perf_counter()
        d = agent.step(sensed)
        samples.append((agent.num_states, 1e3 * (time.perf_counter() - t0)))
        moved = world.act(d, cfg.stay)
    return np.array(samples)


def table(samples: np.ndarray, marks=(50, 100, 250, 500, 1000, 2000)) -> str:
    lines = [f"{'states':>8} {'decisions':>10} {'mean ms':>9} {'median ms':>10} {'p95 ms':>8}"]
    for m in marks:
        sel = samples[(samples[:, 0] >= 0.8 * m) & (samples[:, 0] <= 1.2 * m), 1]
        if sel.size:
            lines.append(f"{m:>8} {sel.size:>10} {sel.mean():>9.2f} {np.median(sel):>10.2f} "
                         f"{np.percentile(sel, 95):>8.2f}")
        else:
            lines.append(f"{m:>8} {'(not reached)':>10}")
    return "\n".join(lines)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=2500)
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    samples = open_plane(args.steps)
    print(f"open plane, {args.steps} decisions, {int(samples[-1, 0])} states at the end "
          f"({time.perf_counter() - t0:.1f} s)")
    print(table(samples))
    try:
        from cogmap.explore import default_config, make_sim, run_agent

        cfg = default_config("mini_warehouse")
        sim = make_sim("mini_warehouse", cfg, 0)
        ep = run_agent(sim, AIMAPPAgent(cfg, seed=0), 150, progress=False)
        sim.close()
        ms = np.array(ep.decision_ms)
        print(f"\npybullet mini warehouse, 150 decisions, {ep.num_states[-1]} states: mean {ms.mean():.2f} ms, "
              f"p95 {np.percentile(ms, 95):.2f} ms (decision only; simulator time excluded)")
    except ImportError as err:  # pragma: no cover
        print(f"(pybullet run skipped: {err})")


if __name__ == "__main__":
    main()

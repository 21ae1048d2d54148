"""Sequence learning (cogmap.inference.fit) on aliased rooms: its time per step of smoothing +
Dirichlet update, and how close the learned model comes to the true one.

1. Time: square rooms of 16-400 places, 5 controls, a 10,000-step random walk, 5 iterations,
   B learned; microseconds per step of data and iteration, for one run and per restart of 4
   run together.
2. Target: a 5 x 5 room with 8 views (places share views), B learned with A given,
   a 10,000-step random walk for training and a 2,000-step one held out; predictive surprise
   (bits per step) of the learned model against the true model's, for plain EM and for 4
   restarts with annealing, at two prior concentrations (F, a bound on -log evidence, ranks them).

    python bench/fit.py [--steps 10000] [--no-target]
"""

from __future__ import annotations

import argparse
import time

from cogmap.genmodel.demo_models import aliased_room, room_model, room_walk
from cogmap.inference.fit import fit, surprise_bits


def timing(steps: int, iterations: int) -> None:
    print(f"{'places':>7} {'us per step and iteration':>27} {'per restart of 4':>17}")
    for side in (4, 5, 10, 20):
        A, B, _ = aliased_room(side, noise=0.05)
        obs, acts, _ = room_walk(A, B, steps, 0)
        row = []
        for restarts in (1, 4):
            model = room_model(A, B, conc=0.1)
            t0 = time.perf_counter()
            res = fit(model, [(obs, acts)], learn_A=False, learn_B=True, iterations=iterations, tol=0.0,
                      init_counts=1.0, seed=0, restarts=restarts)
            row.append(1e6 * (time.perf_counter() - t0) / (steps * res.iterations * restarts))
        print(f"{side * side:>7} {row[0]:>27.1f} {row[1]:>17.1f}")


def target(steps: int) -> None:
    side, views = 5, 8
    A, B, _ = aliased_room(side, views, noise=0.05)
    n = side * side
    train, held_out = room_walk(A, B, steps, 0)[:2], room_walk(A, B, 2000, 1)[:2]
    true_bits = surprise_bits(room_model(A, B), *held_out)
    print(f"\n{side}x{side} room, {views} views, {steps}-step walk: true model {true_bits:.3f} bits/step held out")
    print(f"{'prior':>7} {'fit':>28} {'final F (nats) per restart':>34} {'learned bits':>13} {'/ true':>7} {'s':>6}")
    for conc in (0.1, 1 / n):
        for name, kw in (("plain EM", {}), ("4 restarts, annealed", dict(restarts=4, anneal_iterations=40))):
            model = room_model(A, B, conc=conc)
            t0 = time.perf_counter()
            res = fit(model, [train], learn_A=False, learn_B=True, iterations=200, init_counts=1.0, seed=0, **kw)
            bits = surprise_bits(model, *held_out)
            Fs = " ".join(f"{f:.0f}" for f in res.restart_free_energy)
            print(f"{conc:>7.3f} {name:>28} {Fs:>34} {bits:>13.3f} {bits / true_bits:>7.3f} "
                  f"{time.perf_counter() - t0:>6.1f}")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=10000)
    ap.add_argument("--iterations", type=int, default=5)
    ap.add_argument("--no-target", action="store_true", help="only the timing table")
    args = ap.parse_args(argv)
    timing(args.steps, args.iterations)
    if not args.no_target:
        target(args.steps)


if __name__ == "__main__":
    main()

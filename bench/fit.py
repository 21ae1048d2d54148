"""Time of sequence learning (cogmap.inference.fit): smoothing + Dirichlet update, per step of data
and iteration, on square rooms of 16-400 places with 5 controls and a 10,000-step random walk.

    python bench/fit.py [--steps 10000]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from cogmap.genmodel import Factor, Modality, ModelSpec, compile
from cogmap.genmodel.demo_models import aliased_room
from cogmap.inference.fit import fit


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=10000)
    ap.add_argument("--iterations", type=int, default=5)
    args = ap.parse_args(argv)
    print(f"{'places':>7} {'us per step and iteration':>27} {'iterations':>11}")
    for side in (4, 5, 10, 20):
        A, B, _ = aliased_room(side, noise=0.05)
        n = side * side
        rng = np.random.default_rng(0)
        s, obs, acts = 0, [], []
        for t in range(args.steps):
            if t:
                acts.append(int(rng.integers(5)))
                s = int(np.argmax(B[:, s, acts[-1]]))
            obs.append([int(rng.choice(A.shape[0], p=A[:, s]))])
        model = compile(ModelSpec([Factor("place", n, num_controls=5)], [Modality("view", A.shape[0], ("place",))],
                                  A={"view": A}, B={"place": np.full((n, n, 5), 1 / n)},
                                  pB={"place": np.full((n, n, 5), 0.1)}))
        t0 = time.perf_counter()
        res = fit(model, [(obs, acts)], learn_A=False, learn_B=True, iterations=args.iterations, tol=0.0,
                  init_counts=1.0, seed=0)
        us = 1e6 * (time.perf_counter() - t0) / (args.steps * res.iterations)
        print(f"{n:>7} {us:>27.1f} {res.iterations:>11}")


if __name__ == "__main__":
    main()

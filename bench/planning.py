"""Time one full planning decision on synthetic topological maps.

One decision = MCTS with 30 simulations at depth 10 over all six EFE terms of Eq. 6 plus the
inductive term (goal set), on a grid-like map with 13 controls (12 headings + stay), sparse
transitions with learned-looking Dirichlet counts, a likelihood with uncertain columns for
unvisited states and poses on a 1 m lattice. Run: ``python bench/planning.py``.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # tiny per-node arrays: threads only cost

import time  # noqa: E402

import numpy as np  # noqa: E402

from cogmap.planning import MCTSConfig, decide  # noqa: E402
from cogmap.planning.testing import graph_arrays, lattice_graph  # noqa: E402


def build(n: int, seed: int = 0):
    rng = np.random.default_rng(seed)
    G, poses = lattice_graph(n, rng)
    visited = rng.random(n) < 0.5
    goal = int(rng.integers(n))
    C_states = np.zeros(n)
    C_states[goal] = 1.0
    arrays = graph_arrays(
        G, poses, visited=visited, rng=rng, C_states=[C_states], target_pose=poses[goal],
        goal_states=np.array([goal]), inductive_depth=10,
    )
    start = int(np.argmin(np.linalg.norm(poses - poses.mean(axis=0), axis=1)))
    qs = np.full(n, 1e-12)
    qs[start] = 1.0
    qs[list(G.neighbors(start))[:2]] = 0.05
    qs /= qs.sum()
    obstacles = rng.random(13) < 0.25
    obstacles[12] = False
    return arrays, qs, obstacles, G


def time_decision(arrays, qs, obstacles, repeats: int = 20):
    """Median and minimum wall-clock time and median CPU time (ms) of one decision."""
    cfg = MCTSConfig(depth=10, simulations=30)
    decide(arrays, qs, obstacles, "full", config=cfg, rng=0)  # warm-up
    wall, cpu = [], []
    for r in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        d = decide(arrays, qs, obstacles, "full", config=cfg, rng=r)
        wall.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    ms = lambda x: float(x) * 1e3  # noqa: E731
    return ms(np.median(wall)), ms(np.min(wall)), ms(np.median(cpu)), d.info


def main() -> None:
    print("one decision: MCTS 30 simulations, depth 10, six EFE terms + inductive term")
    print(
        f"{'states':>7} {'edges':>7} {'obs':>6} {'median ms':>10} {'min ms':>8} {'cpu ms':>7} "
        f"{'nodes':>6} {'expanded':>9}"
    )
    for n in (30, 50, 500, 5000):
        arrays, qs, obstacles, G = build(n)
        med, best, cpu, info = time_decision(arrays, qs, obstacles, repeats=30 if n <= 500 else 10)
        print(
            f"{n:>7} {G.number_of_edges():>7} {arrays.num_obs[0]:>6} {med:>10.2f} {best:>8.2f} "
            f"{cpu:>7.2f} {info['nodes']:>6} {info['expansions']:>9}"
        )
    print("reference: the published implementation needs about 600-800 ms at 30-50 states")


if __name__ == "__main__":
    main()

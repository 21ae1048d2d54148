"""Exploration efficiency in the pybullet house (issue 9): coverage efficiency at 90 % coverage.

CE@90 = area covered / distance travelled, both read when LiDAR coverage first reaches 90 %
(``bench/exploration.py`` computes it the same way over every layout and 5 seeds).
Measured on seeds 0 and 2 (``python bench/exploration.py --envs house``): before the sensed-grid
terms 1.86 and 2.07 m2/m (mean 1.97), with them 2.63 and 3.12 (mean 2.88); the oracle tour
reaches 3.89 and 3.78. The threshold 2.3 lies between the two means (0.3 above the old one,
0.6 below the new one), so the test fails if the agent falls back to visiting the map node by
node.
"""

from __future__ import annotations

import numpy as np

from cogmap.agent.aimapp import AIMAPPAgent
from cogmap.explore import coverage_tracker, default_config, make_sim, run_agent

THRESHOLD = 2.3


def _ce_at_90(env: str, seed: int, steps: int) -> tuple[float | None, float]:
    cfg = default_config(env)
    sim = make_sim(env, cfg, seed)
    try:
        agent = AIMAPPAgent(cfg, seed=seed)
        tracker = coverage_tracker(sim)
        ep = run_agent(sim, agent, steps, progress=False, stop=lambda d: tracker.coverage >= 0.9)
        free = tracker.total * sim.grid.resolution**2
        cov = np.asarray(ep.coverage)
        hit = np.flatnonzero(cov >= 0.9)
        if hit.size == 0:
            return None, float(cov[-1])
        i = int(hit[0])
        return float(cov[i] * free / ep.distance[i]), float(cov[i])
    finally:
        sim.close()


def test_house_exploration_reaches_90_percent_efficiently():
    results = [_ce_at_90("house", seed, 200) for seed in (0, 2)]
    assert all(ce is not None and cov >= 0.9 for ce, cov in results), results
    assert np.mean([ce for ce, _ in results]) >= THRESHOLD, results


def test_exploration_page_python_blocks_run():
    import re
    from pathlib import Path

    page = Path(__file__).resolve().parents[2] / "docs" / "exploration.md"
    code = re.findall(r"```python\n(.*?)```", page.read_text(), flags=re.S)
    assert code
    namespace: dict = {}
    for i, block in enumerate(code):
        exec(compile(block, f"exploration.md[block {i}]", "exec"), namespace)
    assert namespace["objective"].names == ("sensed_info_gain", "inductive", "collision")
    near, far = namespace["sg"].unseen_area(namespace["grid"], [[0.0, 0.0], [0.0, -3.0]])
    assert near < far

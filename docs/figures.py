"""Regenerate the pictures of docs/tutorial-aimapp.md: one exploration and one goal run.

    python docs/figures.py          # writes docs/img/aimapp/*.png and docs/img/aimapp/summary.json
"""

from __future__ import annotations

import json
import shutil
import tempfile
from pathlib import Path

import numpy as np

from cogmap.explore import explore
from cogmap.goal import reach_goal

OUT = Path(__file__).resolve().parent / "img" / "aimapp"


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        run = Path(tmp) / "explore"
        explored = explore("house", steps=200, seed=0, out=run, progress=True)
        for name in ("map.png", "coverage.png"):
            shutil.copy(run / name, OUT / f"explore-{name}")
        # the goal: the stored observation first seen farthest from the start
        from cogmap.goal import load_agent

        agent, _ = load_agent(run)
        visited = np.flatnonzero(agent.model.live_pA(0).max(axis=0) > 2 * agent.cfg.prior_count)
        far = visited[np.argmax(np.hypot(*(agent.poses[visited] - agent.poses[0]).T))]
        goal_obs = int(agent.model.live_A(0)[:, far].argmax())
        shutil.copy(run / "observations" / f"{goal_obs:04d}.png", OUT / "goal-image.png")
        reached = reach_goal(run, goal_image=str(OUT / "goal-image.png"), steps=80, out=run / "goal")
        shutil.copy(run / "goal" / "map.png", OUT / "goal-map.png")
    (OUT / "summary.json").write_text(json.dumps({"explore": explored, "goal": reached}, indent=1))
    print(json.dumps({"explore": explored, "goal": reached}, indent=1))


if __name__ == "__main__":
    main()

"""``cogmap drone fly``: seeded episodes in one field, written to a run directory.

Seed S fixes the field (``make_field(S)``); episode i flies from the start to the target drawn with
``default_rng([S, i])`` and the agent's generator is seeded with ``[S, i]`` too, so any episode can be
re-flown alone. The run directory holds ``flight.csv`` (one row per step), ``metrics.json`` (per
episode and the summary), ``run.json`` (settings, versions, commit) and top/side PNGs of the first
flights.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np

from cogmap.envs.drone_episode import EpisodeLimits, fly_episode, summarise

from .methods import make_policy


def episode_target(sim, seed: int, episode: int) -> np.ndarray:
    return sim.sample_target(np.random.default_rng([seed, episode]))


def fly_run(seed: int = 0, episodes: int = 1, out=None, method: str = "agent", end_on_collision: bool = False,
            pictures: int = 3, progress: bool = False, first_episode: int = 0) -> dict:
    """Fly ``episodes`` episodes of ``method``; write the run directory when ``out`` is given.
    Returns ``{"summary": ..., "episodes": [...]}``."""
    from cogmap.envs.drone_sim import DroneConfig, DroneSim

    sim = DroneSim(seed, DroneConfig(end_on_collision=end_on_collision))
    rows: list[dict] = []
    eps: list[dict] = []
    out = Path(out) if out is not None else None
    try:
        it = range(first_episode, first_episode + episodes)
        if progress:
            from tqdm import tqdm

            it = tqdm(it, desc=f"drone {method}", unit="episode")
        for i in it:
            tgt = episode_target(sim, seed, i)
            policy = make_policy(method, seed=[seed, i])

            def log(row, i=i):
                rows.append({"episode": i, **{k: (round(v, 4) if isinstance(v, float) else v) for k, v in row.items()}})

            ep = fly_episode(sim, policy, tgt, EpisodeLimits(), log=log)
            ep["episode"] = i
            eps.append(ep)
            if out is not None and len(eps) <= pictures:
                from cogmap.envs.drone_render import save_flight_pngs

                save_flight_pngs(sim.field, np.array(sim.path), tgt, out, prefix=f"flight_{i:03d}",
                                 title=f"{method}, field {seed}, episode {i}: {ep['outcome']}, "
                                       f"{ep['collisions']} collision(s)")
    finally:
        sim.close()
    result = {"summary": summarise(eps), "episodes": eps}
    if out is not None:
        from cogmap.runs import write_manifest

        out.mkdir(parents=True, exist_ok=True)
        if rows:
            with open(out / "flight.csv", "w", newline="") as fh:
                w = csv.DictWriter(fh, fieldnames=list(rows[0]))
                w.writeheader()
                w.writerows(rows)
        (out / "metrics.json").write_text(json.dumps(result, indent=1, allow_nan=False, default=float))
        write_manifest(out, command="drone fly", seed=seed, episodes=episodes, first_episode=first_episode,
                       method=method, end_on_collision=end_on_collision)
    return result

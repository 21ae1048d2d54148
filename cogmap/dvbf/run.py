"""``cogmap dvbf slam``: online SLAM on one seeded maze, written to a run directory.

The directory holds ``run.json`` (settings, seed, versions, commit), ``model.npz`` + ``model.json``
(q(M) and the emission network as arrays, no pickle), ``trajectory.csv`` (true, inferred and
dead-reckoned poses per step), ``metrics.json`` and ``error.png`` (localisation error against path
integration) and ``map.png`` (the maze, both trajectories and the final particles).
"""

from __future__ import annotations

import csv
import json
from dataclasses import asdict
from pathlib import Path

import numpy as np

from cogmap.envs.maze import make_maze
from cogmap.envs.maze_sim import ROBOT_NOISE, ActuationNoise
from cogmap.envs.maze_traversal import traverse
from cogmap.genmodel.dvbf import maze_config
from cogmap.inference.dvbf_files import save_params
from cogmap.inference.online_slam import SLAMConfig, online_slam, path_integration, pretrain_emission


def slam_run(maze_seed: int, steps: int, out: Path, seed: int = 0, progress: bool = True,
             complexity: str = "moderate", corridor: str = "medium", pretrain_maze: int | None = 0,
             pretrain_steps: int = 2000, pretrain_iters: int = 1500, offline: bool = False,
             noise: ActuationNoise = ROBOT_NOISE, **overrides) -> dict:
    """Run online SLAM (or, with ``offline``, offline SLAM: :mod:`cogmap.inference.offline_slam`) on maze
    ``maze_seed`` for ``steps`` steps and write the run directory to ``out``.

    With ``pretrain_maze`` (default 0), the emission network is first trained with known poses on a
    ``pretrain_steps`` traversal of that maze and then frozen; online SLAM learns only q(M).
    ``overrides`` replace :class:`SLAMConfig` fields (for example ``train_iters``); returns the metrics.

    Parameters
    ----------
    maze_seed : int
        Seed of the evaluation maze.
    steps : int
        Time steps of the traversal (the start counts as step 0).
    out : pathlib.Path
        Run directory (created if missing).
    seed : int
        Seed of the traversal, the filter and the training.
    progress : bool
        Show a progress bar.
    complexity, corridor : str
        Maze family (Table II).
    pretrain_maze : int or None
        Maze seed whose traversal pretrains the emission (Section IV); None learns it online.
    pretrain_steps : int
        Length of that pretraining traversal.
    pretrain_iters : int
        ELBO steps of the pretraining.
    offline : bool
        Optimise all steps at once (:func:`~cogmap.inference.offline_slam.offline_slam`) instead of the online sweep.
    noise : ActuationNoise
        Actuation noise of both traversals; the motion model's heading noise follows its ``rot_std``.
    **overrides
        :class:`SLAMConfig` fields, or :class:`~cogmap.inference.offline_slam.OfflineConfig` fields with ``offline``.

    Returns
    -------
    dict
        The contents of ``metrics.json``: localisation errors (final and mean, of online SLAM and of
        path integration, in maze units), true path length, run time in seconds, number of training
        steps and the final negative ELBO.

    Raises
    ------
    ValueError
        If ``pretrain_maze == maze_seed``.
    """
    if pretrain_maze is not None and pretrain_maze == maze_seed:
        raise ValueError(f"slam_run: the emission is pretrained on maze {pretrain_maze}; evaluate on another maze")
    from cogmap.envs.maze_render import save_error_png, save_maze_png
    from cogmap.runs import write_manifest

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    maze = make_maze(maze_seed, complexity, corridor)
    tr = traverse(maze, steps, seed=seed, noise=noise)  # the seeded operator traversal the filter sees
    model = maze_config(maze.size, maze.map_side, noise.rot_std)
    emission = None
    if pretrain_maze is not None:
        first = traverse(make_maze(pretrain_maze, complexity, corridor), pretrain_steps, seed=seed + 1000, noise=noise)
        emission, _ = pretrain_emission(first.poses, first.scans, model, iters=pretrain_iters, seed=seed)
        overrides = {"freeze_emission": True, **overrides}
    if offline:
        from cogmap.inference.offline_slam import OfflineConfig

        config = OfflineConfig(model=model, seed=seed, **overrides)
    else:
        config = SLAMConfig(model=model, seed=seed, **overrides)
    label = "offline" if offline else "online"
    write_manifest(out, command="dvbf slam", mode=label, maze_seed=maze_seed, complexity=complexity, corridor=corridor,
                   steps=steps, seed=seed, pretrain_maze=pretrain_maze, pretrain_steps=pretrain_steps,
                   pretrain_iters=pretrain_iters,
                   noise=asdict(noise), config=config.to_json())
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=config.rounds if offline else steps - 1, desc=f"{label} SLAM",
                   unit="round" if offline else "step")
    last = [0]

    def tick(t):
        if bar is not None:
            bar.update(t - last[0])
            last[0] = t

    if offline:
        from cogmap.inference.offline_slam import offline_slam

        res = offline_slam(tr.scans, tr.controls, tr.poses[0], config, progress=tick, emission=emission)
    else:
        res = online_slam(tr.scans, tr.controls, tr.poses[0], config, progress=tick, emission=emission)
    if bar is not None:
        bar.close()
    pi = path_integration(tr.poses[0], tr.controls)
    err = np.hypot(*(res.estimates[:, :2] - tr.poses[:, :2]).T)
    err_pi = np.hypot(*(pi[:, :2] - tr.poses[:, :2]).T)
    save_params(res.params, model, out)
    with open(out / "trajectory.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["step", "true_x", "true_y", "true_heading", "est_x", "est_y", "est_heading",
                    "std_x", "std_y", "std_heading", "pi_x", "pi_y", "pi_heading", "error", "error_pi"])
        for t in range(steps):
            w.writerow([t, *np.round(tr.poses[t], 6), *np.round(res.estimates[t], 6), *np.round(res.spreads[t], 6),
                        *np.round(pi[t], 6), round(float(err[t]), 6), round(float(err_pi[t]), 6)])
    metrics = {
        "maze_seed": maze_seed, "steps": steps, "seed": seed, "mode": label, "pretrain_maze": pretrain_maze,
        "error_final": float(err[-1]), "error_pi_final": float(err_pi[-1]),
        "error_mean": float(err.mean()), "error_pi_mean": float(err_pi.mean()),
        "path_length": float(np.sum(np.hypot(*np.diff(tr.poses[:, :2], axis=0).T))),
        "seconds": res.seconds, "training_steps": len(res.losses),
        "final_negative_elbo": float(res.losses[-1]) if len(res.losses) else None,
    }
    (out / "metrics.json").write_text(json.dumps(metrics, indent=1))
    save_error_png(err, err_pi, out / "error.png", label)
    save_maze_png(maze, out / "map.png", paths=[("true", tr.poses, "k"),
                                                (f"DVBF-LM {label}", res.estimates, "tab:blue"),
                                                ("path integration", pi, "tab:red")],
                  particles=res.particles, title=f"maze {maze_seed}: {label} SLAM, {steps} steps")
    return metrics


def explore_run(maze_seed: int, out: Path, steps: int | None = None, seed: int = 0, complexity: str = "simple",
                corridor: str = "small", methods=("mi", "random", "frontier"), cache_dir=None,
                progress: bool = True, **overrides) -> dict:
    """``cogmap dvbf explore``: explore maze ``maze_seed`` with the DVBF-LM agent and the baselines from the same
    start for ``steps`` steps (default: the Table II budget) and write the run directory ``out``.

    The directory holds ``run.json``, ``model.npz`` + ``model.json`` (the first MI agent's final q(M) and emission),
    ``trajectory.csv`` (per method and step: true pose, the agent's estimate, control), ``metrics.json``
    (exploration ratio at the budget, its curve, information gain, planning time), ``path.png`` (the paths on
    the maze) and ``ratio.png`` (exploration ratio and information gain against the steps).
    ``overrides`` replace :class:`~cogmap.dvbf.explore.ExploreConfig` fields.

    Parameters
    ----------
    maze_seed : int
        Seed of the maze (not 0: the emission is pretrained there).
    out : pathlib.Path
        Run directory (created if missing).
    steps : int, optional
        Time steps per method; default the maze's Table II step budget.
    seed : int
        Seed of the start pose, the actuation noise and the agents.
    complexity, corridor : str
        Maze family (Table II).
    methods : sequence of str
        Any of ``"mi"``, ``"mi-pull"`` (the DVBF-LM agent with the frontier pull), ``"random"``, ``"frontier"``.
    cache_dir : path, optional
        Where the pretrained emission is cached; default :func:`cogmap.dvbf.explore.cache_dir`.
    progress : bool
        Show a progress bar per method.
    **overrides
        :class:`~cogmap.dvbf.explore.ExploreConfig` fields (``mi`` defaults to
        :data:`~cogmap.dvbf.explore.STUDY_MI`).

    Returns
    -------
    dict
        The contents of ``metrics.json``: the maze, budget and tiles, each method's
        :meth:`~cogmap.envs.maze_episode.ExploreResult.metrics`, and ``ratio_at_budget`` (method ->
        exploration ratio at the last step).

    Raises
    ------
    ValueError
        If ``maze_seed == 0``, or from :class:`~cogmap.dvbf.explore.ExploreConfig` for bad settings.
    """
    from cogmap.envs.maze_episode import ratio_at
    from cogmap.envs.maze_render import save_maze_png, save_ratio_png
    from cogmap.runs import write_manifest

    from .explore import STUDY_MI, explore, method_config, pretrained_emission
    from .explore import cache_dir as cache_dir_default

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    maze = make_maze(maze_seed, complexity, corridor)
    steps = maze.step_budget if steps is None else int(steps)
    if maze_seed == 0:
        raise ValueError("explore_run: the emission is pretrained on maze 0; explore another maze")
    overrides = {"mi": STUDY_MI, **overrides}
    cfgs = {m: method_config(m, seed=seed, **overrides) for m in methods}
    write_manifest(out, command="dvbf explore", maze_seed=maze_seed, complexity=complexity, corridor=corridor,
                   steps=steps, seed=seed, noise=asdict(ROBOT_NOISE), configs={m: c.to_json() for m, c in cfgs.items()})
    needs_model = any(c.method == "mi" or c.learn_map for c in cfgs.values())
    emission = pretrained_emission(cache_dir or cache_dir_default()) if needs_model else None
    results, metrics = {}, {"maze_seed": maze_seed, "complexity": complexity, "corridor": corridor, "steps": steps,
                            "budget": maze.step_budget, "tiles": maze.tiles, "seed": seed, "methods": {}}
    for m, c in cfgs.items():
        res = explore(maze, steps, c, emission=emission, progress=progress, desc=m)
        results[m] = res
        metrics["methods"][m] = res.metrics(steps)
    agent = next((m for m in ("mi", "mi-pull") if m in results and results[m].params is not None), None)
    if agent is not None:  # the first DVBF-LM agent's map (the paper's, else the one with the pull)
        save_params(results[agent].params, results[agent].model, out)
    with open(out / "trajectory.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["method", "step", "true_x", "true_y", "true_heading", "est_x", "est_y", "est_heading",
                    "turn", "forward"])
        for m, r in results.items():
            for t in range(len(r.poses)):
                est = r.estimates[t] if r.estimates is not None else (np.nan,) * 3
                u = r.controls[t] if t < len(r.controls) else (np.nan, np.nan)
                w.writerow([m, t, *np.round(r.poses[t], 6), *np.round(est, 6), *np.round(u, 6)])
    metrics["ratio_at_budget"] = {m: ratio_at(r.ratio_curve, steps - 1) for m, r in results.items()}
    (out / "metrics.json").write_text(json.dumps(metrics, indent=1))
    colours = {"mi": "tab:blue", "mi-pull": "tab:purple", "random": "tab:red", "frontier": "tab:green"}
    save_maze_png(maze, out / "path.png", paths=[(f"{m} ({metrics['ratio_at_budget'][m]:.2f})", r.poses,
                                                  colours.get(m, "k")) for m, r in results.items()],
                  title=f"maze {maze_seed} ({complexity}, {corridor}): {steps} steps")
    save_ratio_png(results, maze, out / "ratio.png")
    return metrics

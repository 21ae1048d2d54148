"""Navigation in a learned DVBF-LM (paper Section V): hybrid A* on the learned map, executed in the
simulator, against the same planner in the true simulator.

For one maze: a 5 x 5 grid of free poses, ordered pairs of them (all, or a seeded subset), and for
each pair two plans with :func:`cogmap.planning.hybrid_astar.plan_path`: one whose scans are the
emission's predictions at the map mean (``learned``), one whose scans are the simulator's ray casts
(``true``, the paper's upper bound in Figure 6c). Each plan's controls are executed open loop in the
pybullet maze without actuation noise (the paper executes "the obtained controls"; it does not
re-plan); success = final position within 0.05 of the goal (Section V-B b).

The learned model: a ``cogmap dvbf slam`` run directory (``model_dir``), or by default a model learnt
with known poses (:func:`learn_model`): q(M) and the emission fit by the ELBO to a traversal of the
maze with its true poses. That is mapping, not SLAM; the paper uses the models of its SLAM runs.
"""

from __future__ import annotations

import csv
import json
import time
from dataclasses import asdict
from pathlib import Path

import numpy as np

from cogmap.envs.maze import Maze, make_maze
from cogmap.envs.maze_poses import GRID, SUCCESS_RADIUS, execute, grid_poses, outcome_row, pose_pairs, summarise
from cogmap.envs.maze_render import save_plans_png
from cogmap.genmodel.dvbf_scan import scan_models
from cogmap.inference.goal_encoding import encode_goals
from cogmap.planning.hybrid_astar import HybridAStarConfig, cost_grid, plan_path


def learn_model(maze: Maze, steps: int = 2000, iters: int = 3000, seed: int = 0, pretrain_maze: int | None = None,
                pretrain_steps: int = 2000, pretrain_iters: int = 1500, hidden: int = 64, map_side: int | None = None,
                sigma_e: float = 0.03):
    """A DVBF-LM of ``maze`` learnt from a seeded ``steps``-step traversal with its true poses: q(M)
    and the emission fit together by the ELBO for ``iters`` Adam steps (with ``pretrain_maze``, the
    emission is instead pretrained on that maze and frozen, as ``cogmap dvbf slam`` does).

    ``map_side`` defaults to twice Table II's (50 x 50 for the unit maze), ``sigma_e`` (emission std in
    training) to 0.03. Measured on maze 1 (12 pairs, map-mean reading): with the settings of ``cogmap
    dvbf slam`` (25 x 25, emission pretrained on maze 0 and frozen, std 0.1, 1,500 Adam steps) 5 plans
    hit a wall at blurred wall ends; with these defaults none did. Which change matters most was not
    separated.

    Parameters
    ----------
    maze : Maze
        The maze to map.
    steps : int
        Length of the seeded traversal.
    iters : int
        Adam steps on the ELBO (Eq. 3).
    seed : int
        Seed of the traversal (the fit uses ``seed + 1``).
    pretrain_maze : int, optional
        Maze (same family) on which to pretrain and then freeze the emission.
    pretrain_steps, pretrain_iters : int
        Traversal length and Adam steps of that pretraining.
    hidden : int
        Hidden units of the emission network.
    map_side : int, optional
        Map grid cells per side; default twice the Table II side.
    sigma_e : float
        Emission std used in training, in maze units.

    Returns
    -------
    params : DVBFParams
        The fitted q(M) and emission.
    cfg : DVBFConfig
        The model.
    info : dict
        How it was learnt (steps, iterations, map side, ``final_negative_elbo``, ``train_s`` seconds).

    Raises
    ------
    ValueError
        If ``pretrain_maze`` is ``maze`` itself.
    """
    from cogmap.envs.maze_sim import ROBOT_NOISE
    from cogmap.envs.maze_traversal import traverse
    from cogmap.genmodel.dvbf import DVBFConfig
    from cogmap.inference.online_slam import fit_known_poses

    if pretrain_maze is not None and pretrain_maze == maze.seed:
        raise ValueError(f"learn_model: the emission is pretrained on maze {pretrain_maze}; learn another maze")
    side = 2 * maze.map_side if map_side is None else int(map_side)
    cfg = DVBFConfig(extent=maze.size, map_side=side, hidden=hidden, sigma_e=sigma_e)
    tic = time.perf_counter()
    emission = None
    if pretrain_maze is not None:
        first = traverse(make_maze(pretrain_maze, maze.complexity, maze.corridor), pretrain_steps, seed=seed + 1000,
                         noise=ROBOT_NOISE)
        params, _ = fit_known_poses(first.poses, first.scans, cfg, iters=pretrain_iters, seed=seed)
        emission = params.emission
    tr = traverse(maze, steps, seed=seed, noise=ROBOT_NOISE)
    params, losses = fit_known_poses(tr.poses, tr.scans, cfg, iters=iters, seed=seed + 1, emission=emission)
    info = {"source": "known-pose mapping", "steps": steps, "iters": iters, "map_side": side, "sigma_e": sigma_e,
            "hidden": hidden, "pretrain_maze": pretrain_maze,
            "pretrain_iters": pretrain_iters if pretrain_maze is not None else None,
            "final_negative_elbo": float(losses[-1]), "train_s": time.perf_counter() - tic}
    return params, cfg, info


def navigate_pairs(maze: Maze, scan_fns: dict, poses: np.ndarray, pairs, config: HybridAStarConfig,
                   progress=None, targets: dict | None = None) -> tuple[list[dict], dict]:
    """Plan every pair with every scan function (``{"learned": fn, "true": fn}``) and execute each plan
    in a noise-free simulator. Returns per-plan rows and ``{"paths": {model: [(pair, Plan, executed,
    goal)]}, "grid_s": {model: seconds to scan the heuristic's grid}}``. With ``targets[model]``, that
    model plans to those poses instead (e.g. goals inferred from observations) and is still judged
    against the true goal ``poses[j]``.

    Parameters
    ----------
    maze : Maze
        The maze.
    scan_fns : dict of str to callable
        Model name -> ``scan(poses (K, 3)) -> ranges (K, n_beams)`` (see :func:`cogmap.genmodel.dvbf_scan.scan_models`).
    poses : numpy.ndarray, shape (n_poses, 3)
        Candidate start and goal poses.
    pairs : iterable of (int, int)
        ``(start index, goal index)``.
    config : HybridAStarConfig
        Planner settings.
    progress : callable, optional
        Called with the number of pairs done.
    targets : dict of str to numpy.ndarray, optional
        Model name -> planning goals ``(n_poses, 3)``, one per pose index.

    Returns
    -------
    rows : list of dict
        One per (pair, model), from :func:`~cogmap.envs.maze_poses.outcome_row`: ``found``,
        ``success`` (final position within :data:`~cogmap.envs.maze_poses.SUCCESS_RADIUS` of the goal,
        Section V-B), errors, lengths, planner counts and ``plan_s`` seconds.
    extra : dict
        ``paths`` and ``grid_s`` as above.
    """
    from cogmap.envs.maze_sim import MazeSim

    rows, paths = [], {name: [] for name in scan_fns}
    grids = {}
    sim = MazeSim(maze)
    try:
        for name, fn in scan_fns.items():
            t = time.perf_counter()
            grids[name] = (cost_grid(fn, maze.size, config.cell), time.perf_counter() - t)
        targets = targets or {}
        for n, (i, j) in enumerate(pairs):
            for name, fn in scan_fns.items():
                goal = targets[name][j] if name in targets else poses[j]
                plan = plan_path(poses[i], goal, fn, maze.size, config, grid=grids[name][0])
                executed, blocked = execute(sim, poses[i], plan.controls) if plan.found else (poses[i][None], 0)
                rows.append(outcome_row((i, j), name, plan, executed, blocked, poses[j]))
                paths[name].append(((i, j), plan, executed, poses[j]))
            if progress is not None:
                progress(n + 1)
    finally:
        sim.close()
    return rows, {"paths": paths, "grid_s": {k: v[1] for k, v in grids.items()}}


def navigate_run(maze_seed: int, out: Path | None = None, pairs: int | None = 40, seed: int = 0,
                 complexity: str = "moderate", corridor: str = "medium", model_dir: Path | None = None,
                 map_steps: int = 2000, map_iters: int = 3000, pretrain_maze: int | None = None,
                 pretrain_iters: int = 1500, config: HybridAStarConfig | None = None, progress: bool = True,
                 model=None, grid: int = GRID, observation_goals: bool = False) -> dict:
    """Navigation on maze ``maze_seed``: learn (or load) the model, plan and execute ``pairs`` seeded
    pose pairs (None: all ordered pairs; 600 for the 5 x 5 grid) in the learned model and in the true
    simulator, and write the run directory to ``out`` (if given). ``model``: an already learnt
    ``(params, cfg, info)``; ``grid``: poses per side (at most the maze's cells per side). Returns
    the metrics.

    Parameters
    ----------
    maze_seed : int
        Seed of the maze.
    out : pathlib.Path, optional
        Run directory (``run.json``, ``model.npz``/``model.json``, ``poses.csv``, ``pairs.csv``,
        ``metrics.json``, ``paths.png``); nothing is written if None.
    pairs : int, optional
        Seeded pairs to plan; None for all ordered pairs.
    seed : int
        Seed of the poses' headings, the pairs and the learnt model.
    complexity, corridor : str
        Maze family (Table II).
    model_dir : pathlib.Path, optional
        A run directory to load the model from (:func:`~cogmap.inference.dvbf_files.load_params`).
    map_steps, map_iters : int
        Traversal length and Adam steps of :func:`learn_model`.
    pretrain_maze : int, optional
        Maze to pretrain the emission on (see :func:`learn_model`).
    pretrain_iters : int
        Adam steps of that pretraining.
    config : HybridAStarConfig, optional
        Planner settings; default ``HybridAStarConfig()``.
    progress : bool
        Show a progress bar.
    model : tuple, optional
        An already learnt ``(params, cfg, info)``; takes precedence over ``model_dir``.
    grid : int
        Poses per side.
    observation_goals : bool
        Also plan pose-to-observation: to the pose
        :func:`cogmap.inference.goal_encoding.encode_goals` finds for each goal's scan, in the ``learned`` reading
        (world ``observation``; success still at the true goal).

    Returns
    -------
    dict
        The maze, seed, number of pairs, :data:`SUCCESS_RADIUS`, the model's ``info``, ``grid_s``
        and the entries of :func:`~cogmap.envs.maze_poses.summarise`; with ``observation_goals`` also ``goal_errors``.

    Raises
    ------
    ValueError
        If the model's extent differs from the maze's side, or from :func:`cogmap.envs.maze_poses.grid_poses`.
    """
    from cogmap.envs.maze_sim import MazeSim

    config = config or HybridAStarConfig()
    maze = make_maze(maze_seed, complexity, corridor)
    if model is not None:
        params, cfg, info = model
    elif model_dir is not None:
        from cogmap.inference.dvbf_files import load_params

        params, cfg = load_params(Path(model_dir))
        info = {"source": f"run directory {model_dir}"}
    else:
        params, cfg, info = learn_model(maze, map_steps, map_iters, seed=seed, pretrain_maze=pretrain_maze,
                                        pretrain_iters=pretrain_iters)
    if abs(cfg.extent - maze.size) > 1e-9:
        raise ValueError(f"navigate_run: the model covers a world of side {cfg.extent}, maze {maze_seed} has "
                         f"side {maze.size}")
    poses = grid_poses(maze, grid, seed)
    chosen = pose_pairs(len(poses), pairs, seed)
    true_sim = MazeSim(maze)
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=len(chosen), desc=f"maze {maze_seed} pairs", unit="pair")
    try:
        worlds, targets, encoded = scan_models(params, cfg, true_sim), {}, None
        if observation_goals:
            encoded = encode_goals(true_sim, poses, params, cfg)
            worlds["observation"], targets["observation"] = worlds["learned"], encoded["poses"]
        rows, extra = navigate_pairs(maze, worlds, poses, chosen, config,
                                     progress=(lambda n: bar.update(1)) if bar else None, targets=targets)
        for r in rows:
            r["goal_estimate_error"] = encoded["errors"][r["goal"]] if r["model"] == "observation" else None
    finally:
        true_sim.close()
        if bar is not None:
            bar.close()
    metrics = {"maze_seed": maze_seed, "complexity": complexity, "corridor": corridor, "seed": seed,
               "pairs": len(chosen), "success_radius": SUCCESS_RADIUS, "model": info,
               "grid_s": extra["grid_s"], **summarise(rows)}
    if encoded is not None:
        metrics["goal_errors"] = encoded["errors"]
    if out is not None:
        _write_run(Path(out), maze, params, cfg, poses, rows, extra["paths"], metrics, config, locals_=dict(
            maze_seed=maze_seed, pairs=pairs, seed=seed, complexity=complexity, corridor=corridor,
            model_dir=str(model_dir) if model_dir else None, map_steps=map_steps, map_iters=map_iters,
            pretrain_maze=pretrain_maze, pretrain_iters=pretrain_iters))
    return metrics


def _write_run(out: Path, maze, params, cfg, poses, rows, paths, metrics, config, locals_) -> None:
    from cogmap.inference.dvbf_files import save_params
    from cogmap.runs import write_manifest

    out.mkdir(parents=True, exist_ok=True)
    write_manifest(out, command="dvbf navigate", planner=json.loads(json.dumps(asdict(config))), **locals_)
    save_params(params, cfg, out)
    np.savetxt(out / "poses.csv", poses, delimiter=",", header="x,y,heading", comments="", fmt="%.6f")
    keys = list(rows[0]) if rows else []
    with open(out / "pairs.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        for r in rows:
            w.writerow({k: (round(v, 6) if isinstance(v, float) else v) for k, v in r.items()})
    (out / "metrics.json").write_text(json.dumps(metrics, indent=1))
    save_plans_png(maze, paths, out / "paths.png", SUCCESS_RADIUS)

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
from cogmap.envs.maze_sim import ActuationNoise
from cogmap.envs.maze_traversal import traverse
from cogmap.genmodel.dvbf import DVBFConfig

from .slam import SLAMConfig, online_slam, path_integration, pretrain_emission

NOISE = ActuationNoise(rot_std=0.005, trans_frac=0.05)


def save_params(params, cfg: DVBFConfig, out: Path) -> None:
    """``model.npz`` (every array leaf, by its pytree path) and ``model.json`` (config and leaf names)."""
    import equinox as eqx
    import jax

    leaves = jax.tree_util.tree_leaves_with_path(eqx.filter(params, eqx.is_array))
    arrays = {jax.tree_util.keystr(path).strip(".").replace("[", "_").replace("]", "").replace(".", "/"): np.asarray(v)
              for path, v in leaves}
    np.savez_compressed(out / "model.npz", **arrays)
    (out / "model.json").write_text(json.dumps({"config": asdict(cfg), "arrays": sorted(arrays)}, indent=1))


def load_params(out: Path):
    """Rebuild the parameters written by :func:`save_params`; returns ``(params, cfg)``."""
    import equinox as eqx
    import jax

    from cogmap.inference.elbo import init_params

    meta = json.loads((Path(out) / "model.json").read_text())
    c = meta["config"]
    cfg = DVBFConfig(**{**c, "sigma_t": tuple(c["sigma_t"]), "radii": tuple(c["radii"])})
    template = init_params(cfg, jax.random.PRNGKey(0))
    data = np.load(Path(out) / "model.npz")
    arr, static = eqx.partition(template, eqx.is_array)
    paths = jax.tree_util.tree_leaves_with_path(arr)
    names = [jax.tree_util.keystr(p).strip(".").replace("[", "_").replace("]", "").replace(".", "/") for p, _ in paths]
    new_leaves = [jax.numpy.asarray(data[n]) for n in names]
    arr = jax.tree_util.tree_unflatten(jax.tree_util.tree_structure(arr), new_leaves)
    return eqx.combine(arr, static), cfg


def slam_run(maze_seed: int, steps: int, out: Path, seed: int = 0, progress: bool = True,
             complexity: str = "moderate", corridor: str = "medium", pretrain_maze: int | None = 0,
             pretrain_steps: int = 2000, pretrain_iters: int = 1500, **overrides) -> dict:
    """Run online SLAM on maze ``maze_seed`` for ``steps`` steps and write the run directory to ``out``.

    With ``pretrain_maze`` (default 0), the emission network is first trained with known poses on a
    ``pretrain_steps`` traversal of that maze and then frozen; online SLAM learns only q(M).
    ``overrides`` replace :class:`SLAMConfig` fields (for example ``train_iters``); returns the metrics.
    """
    if pretrain_maze is not None and pretrain_maze == maze_seed:
        raise ValueError(f"slam_run: the emission is pretrained on maze {pretrain_maze}; evaluate on another maze")
    from cogmap.envs.maze_render import save_maze_png
    from cogmap.runs import write_manifest

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    maze = make_maze(maze_seed, complexity, corridor)
    tr = traverse(maze, steps, seed=seed, noise=NOISE)
    model = DVBFConfig(extent=maze.size, map_side=maze.map_side, hidden=64,
                       sigma_t=(0.0005, 0.0005, NOISE.rot_std))
    emission = None
    if pretrain_maze is not None:
        first = traverse(make_maze(pretrain_maze, complexity, corridor), pretrain_steps, seed=seed + 1000, noise=NOISE)
        emission, _ = pretrain_emission(first.poses, first.scans, model, iters=pretrain_iters, seed=seed)
        overrides = {"freeze_emission": True, **overrides}
    config = SLAMConfig(model=model, seed=seed, **overrides)
    write_manifest(out, command="dvbf slam", maze_seed=maze_seed, complexity=complexity, corridor=corridor,
                   steps=steps, seed=seed, pretrain_maze=pretrain_maze, pretrain_steps=pretrain_steps,
                   pretrain_iters=pretrain_iters,
                   noise=asdict(NOISE), config=config.to_json())
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=steps - 1, desc="online SLAM", unit="step")
    last = [0]

    def tick(t):
        if bar is not None:
            bar.update(t - last[0])
            last[0] = t

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
        "maze_seed": maze_seed, "steps": steps, "seed": seed, "pretrain_maze": pretrain_maze,
        "error_final": float(err[-1]), "error_pi_final": float(err_pi[-1]),
        "error_mean": float(err.mean()), "error_pi_mean": float(err_pi.mean()),
        "path_length": float(np.sum(np.hypot(*np.diff(tr.poses[:, :2], axis=0).T))),
        "seconds": res.seconds, "training_steps": len(res.losses),
        "final_negative_elbo": float(res.losses[-1]) if len(res.losses) else None,
    }
    (out / "metrics.json").write_text(json.dumps(metrics, indent=1))
    _error_png(err, err_pi, out / "error.png")
    save_maze_png(maze, out / "map.png", paths=[("true", tr.poses, "k"), ("DVBF-LM online", res.estimates, "tab:blue"),
                                                ("path integration", pi, "tab:red")],
                  particles=res.particles, title=f"maze {maze_seed}: online SLAM, {steps} steps")
    return metrics


def _error_png(err, err_pi, filename) -> None:
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 3.5))
    try:
        ax.plot(err, label="DVBF-LM online SLAM", c="tab:blue")
        ax.plot(err_pi, label="path integration", c="tab:red")
        ax.set_xlabel("step")
        ax.set_ylabel("localisation error (maze side = 1)")
        ax.legend()
        fig.tight_layout()
        fig.savefig(filename, dpi=110)
    finally:
        plt.close(fig)

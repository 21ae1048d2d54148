"""Command line: ``cogmap explore``, ``cogmap goal``, ``cogmap compare-inference``,
``cogmap drone fly``, ``cogmap dvbf slam|navigate|explore``, ``cogmap reproduce``.

Every error ends the command with one line on stderr naming the problem and exit status 2
(``--debug`` shows the traceback instead); ``cogmap --version`` prints the version.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from . import __version__
from .argtypes import (
    MAX_DECISIONS,
    MAX_DVBF_STEPS,
    MAX_EPISODES,
    MAX_PAIRS,
    MAX_SEED,
    OneLineParser,
    bounded_float,
    bounded_int,
    one_line,
    seed_int,
)
from .plugins import import_plugins
from .runguard import add_run_options, run_command

#: ``--steps`` of explore and goal, ``--patience`` and ``--checkpoint-every``
decisions = bounded_int(1, MAX_DECISIONS, "MAX_DECISIONS")
episodes = bounded_int(1, MAX_EPISODES, "MAX_EPISODES")
episode_index = bounded_int(0, MAX_EPISODES, "MAX_EPISODES")
dvbf_steps = bounded_int(1, MAX_DVBF_STEPS, "MAX_DVBF_STEPS")


def _compare_steps(text: str) -> int:
    """``compare-inference --steps``: 1 .. :data:`cogmap.inference.compare.MAX_STEPS` (imported on use)."""
    from cogmap.inference.compare import MAX_STEPS

    return bounded_int(1, MAX_STEPS, "cogmap.inference.compare.MAX_STEPS")(text)


def _slip(text: str) -> float:
    from .envs.robot import MAX_SLIP

    return bounded_float(-MAX_SLIP, MAX_SLIP, "MAX_SLIP")(text)


def _heading_bias(text: str) -> float:
    from .envs.robot import MAX_HEADING_BIAS

    return bounded_float(-MAX_HEADING_BIAS, MAX_HEADING_BIAS, "MAX_HEADING_BIAS")(text)


def _pretrain_maze(text: str) -> int:
    return bounded_int(-1, MAX_SEED, "MAX_SEED")(text)


def _explore(args) -> int:
    from dataclasses import replace

    from .envs import OdometryNoise
    from .explore import default_config, explore

    out = Path(args.out)
    noise = OdometryNoise(slip=args.slip, heading_bias=args.heading_bias)
    config = replace(default_config(args.env), encoder=args.encoder, scheme=args.scheme)
    metrics = explore(args.env, steps=args.steps, seed=args.seed, out=out, progress=not args.quiet,
                      patience=args.patience, noise=noise, config=config, checkpoint_every=args.checkpoint_every,
                      resume=args.resume)
    print(json.dumps(metrics, indent=1))
    print(f"run written to {out}/ (map.png, coverage.png, map.graphml, trajectory.csv, metrics.json, model.*)")
    return 0


def _explore_check(args) -> None:
    """The environment exists before anything starts (a layout file is read, every entry checked and
    bounded); the checks that rasterise a building run in the run itself, under --time-limit."""
    if not args.resume:
        from . import inference
        from .explore import check_env

        check_env(args.env)
        if args.scheme not in inference.available():
            raise ValueError(f"unknown inference scheme {args.scheme!r} (--scheme); registered: "
                             f"{', '.join(inference.available())}")


def _goal(args) -> int:
    from .goal import reach_goal

    result = reach_goal(Path(args.run), goal_image=args.goal_image, goal_obs=args.goal_obs, steps=args.steps,
                        seed=args.seed, out=Path(args.out) if args.out else None, progress=not args.quiet)
    print(json.dumps(result, indent=1))
    return 0 if result["reached"] else 1


def _explore_resume_state(out: Path) -> str:
    from .explore import resume_state

    return resume_state(out)


def _goal_check(args) -> None:
    """``--run`` is an exploration run (its run.json says so) before a child starts."""
    from .goal import exploration_manifest

    exploration_manifest(Path(args.run))


def _compare(args) -> int:
    import numpy as np

    from cogmap.inference.compare import compare_inference, format_table, generate_sequence, load_model

    model = load_model(args.model, np.random.default_rng(args.seed), plugins=args.plugin)
    seq = generate_sequence(model, T=args.steps, seed=args.seed)
    rows = compare_inference(model, seq.observations, seq.actions, true_states=seq.states, progress=not args.quiet)
    print(format_table(rows))
    return 0


def _drone_fly(args) -> int:
    from .drone.run import fly_run

    res = fly_run(args.seed, args.episodes, args.out, method=args.method, end_on_collision=args.end_on_collision,
                  pictures=args.pictures, progress=not args.quiet, first_episode=args.first_episode)
    s = res["summary"]
    print(json.dumps({k: (round(v, 4) if isinstance(v, float) else v) for k, v in s.items()}, indent=1))
    if args.out:
        print(f"run written to {args.out}/ (flight.csv, metrics.json, run.json, flight_*_top.png, flight_*_side.png)")
    return 0


def _dvbf(args) -> int:
    from .dvbf.run import slam_run

    pre = None if args.pretrain_maze < 0 else args.pretrain_maze
    metrics = slam_run(args.maze, args.steps, Path(args.out), seed=args.seed, progress=not args.quiet,
                       pretrain_maze=pre, offline=args.offline)
    print(json.dumps(metrics, indent=1))
    print(f"run written to {args.out}/ (model.npz/json, trajectory.csv, metrics.json, error.png, map.png)")
    return 0


def _dvbf_navigate(args) -> int:
    from .dvbf.navigate import navigate_run

    metrics = navigate_run(args.maze, Path(args.out), pairs=args.pairs, seed=args.seed,
                           model_dir=Path(args.model) if args.model else None, progress=not args.quiet,
                           observation_goals=args.observation_goals)
    shown = ("maze_seed", "pairs", "learned", "learned_mean", "true", "observation", "length_ratio",
             "length_ratio_learned_mean")
    print(json.dumps({k: v for k, v in metrics.items() if k in shown}, indent=1))
    print(f"run written to {args.out}/ (model.npz/json, pairs.csv, poses.csv, metrics.json, paths.png)")
    return 0


def _dvbf_explore(args) -> int:
    from .dvbf.run import explore_run

    metrics = explore_run(args.maze, Path(args.out), steps=args.steps, seed=args.seed, complexity=args.complexity,
                          corridor=args.corridor, methods=tuple(args.methods), progress=not args.quiet)
    print(json.dumps({"ratio_at_end": metrics["ratio_at_budget"], "steps": metrics["steps"],
                      "budget": metrics["budget"]}, indent=1))
    print(f"run written to {args.out}/ (model.npz/json, trajectory.csv, metrics.json, path.png, ratio.png)")
    return 0


def _reproduce(args) -> int:
    from .study.runner import run_from_args

    return run_from_args(args)


def build_parser() -> argparse.ArgumentParser:
    p = OneLineParser(prog="cogmap", description="Active-inference navigation toolkit")
    p.add_argument("--version", action="version", version=f"cogmap {__version__}")
    p.add_argument("--debug", action="store_true", help="show the full traceback of an error")
    p.add_argument("--plugin", action="append", default=[], metavar="MODULE",
                   help="import MODULE first (repeatable): its registrations (layouts, schemes, planners, "
                        "EFE terms, encoders) are then known by name")
    sub = p.add_subparsers(dest="command", required=True)

    e = sub.add_parser("explore", help="AIMAPP exploration of a pybullet room")
    e.add_argument("--env", default="mini_warehouse",
                   help="layout name, registered id, or your own building: a layout file (.json) or a plan "
                        "image (.png, dark = wall, 0.05 m per pixel), or a procedural building:KIND:SEED (KIND: "
                        "corridor, office, L, T, U, hall); see docs/tutorial-aimapp.md "
                        "(default: mini_warehouse)")
    e.add_argument("--steps", type=decisions, default=150,
                   help=f"at most this many decisions (default: 150; at most {MAX_DECISIONS})")
    e.add_argument("--patience", type=bounded_int(0, MAX_DECISIONS, "MAX_DECISIONS"), default=20,
                   help="end once the map has not grown and no state was visited for the first time in this "
                        "many decisions (default: 20; 0: always run --steps)")
    e.add_argument("--seed", type=seed_int, default=0, help=f"start pose, noise and agent seed, 0 .. {MAX_SEED}")
    e.add_argument("--slip", type=_slip, default=0.0,
                   help="odometry drift: fractional over-read of travelled distance, in [-0.5, 0.5] (default: 0; "
                        "0.05 reads 1.05 m per metre)")
    e.add_argument("--heading-bias", type=_heading_bias, default=0.0,
                   help="odometry drift: yaw error in rad per metre travelled, in [-0.5, 0.5] (default: 0)")
    e.add_argument("--encoder", default="ssim", help="observation encoder by name (default: ssim, the paper's; "
                   "others from --plugin modules)")
    e.add_argument("--scheme", default="filter",
                   help="inference scheme that localises the agent: filter (default, the paper's exact filter), "
                   "exact, fpi, vmp, vmp_pymdp, mmp, or one registered by a --plugin module")
    e.add_argument("--out", default="runs/explore", help="run directory (default: runs/explore)")
    e.add_argument("--quiet", action="store_true", help="no progress bar")
    e.add_argument("--checkpoint-every", type=decisions, default=10, metavar="N",
                   help="save the exploration state every N decisions, for --resume (default: 10)")
    add_run_options(e, resume_help="continue the exploration in --out from its last checkpoint, with the settings "
                                   "in its run.json")
    e.set_defaults(func=_explore, out_dir=lambda a: Path(a.out), precheck=_explore_check,
                   resume_state=_explore_resume_state)

    g = sub.add_parser("goal", help="reach a goal observation with a model from an exploration run")
    g.add_argument("--run", required=True, help="directory written by 'cogmap explore'")
    src = g.add_mutually_exclusive_group(required=True)
    src.add_argument("--goal-image", help="PNG of the goal panorama")
    src.add_argument("--goal-obs", type=bounded_int(0, MAX_DECISIONS, "MAX_DECISIONS"),
                     help="id of a stored observation (observations/NNNN.png)")
    g.add_argument("--steps", type=decisions, default=60, help=f"at most this many decisions (default: 60; at most "
                                                                  f"{MAX_DECISIONS})")
    g.add_argument("--seed", type=seed_int, default=0)
    g.add_argument("--out", default=None, help="directory for the goal run (default: <run>/goal)")
    g.add_argument("--quiet", action="store_true")
    add_run_options(g)
    g.set_defaults(func=_goal, out_dir=lambda a: Path(a.out) if a.out else Path(a.run) / "goal",
                   precheck=_goal_check)

    c = sub.add_parser("compare-inference", help="run every registered inference scheme on one model")
    c.add_argument("--model", default="tmaze",
                   help="a built-in model (tmaze, corridor, random), a saved model (PATH of its .npz/.json) "
                        "or a factory (module:function returning a compiled Model, its module loaded with --plugin)")
    c.add_argument("--steps", type=_compare_steps, default=30,
                   help="length of the sampled sequence (default: 30; at most cogmap.inference.compare.MAX_STEPS, "
                        "1000: the cost grows with the square of the steps)")
    c.add_argument("--seed", type=seed_int, default=0)
    c.add_argument("--quiet", action="store_true", help="no progress bar (it shows on runs longer than a second)")
    c.set_defaults(func=_compare)

    from .drone.methods import METHODS as DRONE_METHODS

    d = sub.add_parser("drone", help="the hierarchical active-inference drone in a 3D pybullet obstacle field")
    dsub = d.add_subparsers(dest="drone_command", required=True)
    f = dsub.add_parser("fly", help="fly seeded episodes and write a run directory")
    f.add_argument("--seed", type=seed_int, default=0, help="field seed; episode i's target is drawn from (seed, i)")
    f.add_argument("--episodes", type=episodes, default=1,
                   help=f"number of episodes (default: 1; at most {MAX_EPISODES})")
    f.add_argument("--first-episode", type=episode_index, default=0, help="index of the first episode (default: 0)")
    f.add_argument("--method", default="agent", choices=DRONE_METHODS)
    f.add_argument("--end-on-collision", action="store_true", help="a collision ends the episode (the honest setting)")
    f.add_argument("--pictures", type=episode_index, default=3,
                   help="top/side PNGs of the first N episodes (default: 3)")
    f.add_argument("--out", default=None, help="run directory (default: print the summary only)")
    f.add_argument("--quiet", action="store_true")
    add_run_options(f)
    f.set_defaults(func=_drone_fly, out_dir=lambda a: Path(a.out) if a.out else None)

    v = sub.add_parser("dvbf", help="DVBF-LM in the LiDAR mazes")
    vsub = v.add_subparsers(dest="dvbf_command", required=True)
    ds = vsub.add_parser("slam", help="online (or offline) SLAM on one seeded maze (unit square), against path "
                                      "integration")
    ds.add_argument("--offline", action="store_true",
                    help="offline SLAM: all steps optimised at once, in rounds of ELBO training and a full "
                         "1,000-particle filter pass (paper Appendix B-I)")
    ds.add_argument("--maze", type=seed_int, default=1, help="maze seed (default: 1)")
    ds.add_argument("--pretrain-maze", type=_pretrain_maze, default=0,
                    help="maze whose traversal with known poses pretrains the emission, then frozen "
                         "(default: 0; -1: learn the emission online from scratch)")
    ds.add_argument("--steps", type=dvbf_steps, default=1000,
                    help=f"traversal length (default: 1000; at most {MAX_DVBF_STEPS})")
    ds.add_argument("--seed", type=seed_int, default=0, help="traversal, noise and filter seed (default: 0)")
    ds.add_argument("--out", default="runs/dvbf-slam", help="run directory (default: runs/dvbf-slam)")
    ds.add_argument("--quiet", action="store_true")
    add_run_options(ds)
    ds.set_defaults(func=_dvbf, out_dir=lambda a: Path(a.out))
    dn = vsub.add_parser("navigate", help="hybrid A* in a learned DVBF-LM, executed in the maze, against planning "
                                          "in the true simulator")
    dn.add_argument("--maze", type=seed_int, default=1, help="maze seed (default: 1)")
    dn.add_argument("--observation-goals", action="store_true",
                    help="also plan to the pose found for each goal's scan (pose-to-observation)")
    dn.add_argument("--pairs", type=bounded_int(1, MAX_PAIRS, "MAX_PAIRS"), default=40,
                    help=f"seeded subset of the {MAX_PAIRS} ordered pairs of the 5 x 5 pose grid (default: 40)")
    dn.add_argument("--model", default=None,
                    help="a 'cogmap dvbf slam' run directory to plan in (default: learn the map with known poses)")
    dn.add_argument("--seed", type=seed_int, default=0,
                    help="pose headings, pair subset and training seed (default: 0)")
    dn.add_argument("--out", default="runs/dvbf-navigate", help="run directory (default: runs/dvbf-navigate)")
    dn.add_argument("--quiet", action="store_true")
    add_run_options(dn)
    dn.set_defaults(func=_dvbf_navigate, out_dir=lambda a: Path(a.out))
    dx = vsub.add_parser("explore", help="exploration by mutual information against a random walk and frontiers")
    dx.add_argument("--maze", type=bounded_int(1, MAX_SEED, "MAX_SEED"), default=1,
                    help="maze seed, not 0 (default: 1)")
    dx.add_argument("--complexity", default="simple", choices=("simple", "moderate", "complex"))
    dx.add_argument("--corridor", default="small", choices=("small", "medium", "large"))
    dx.add_argument("--steps", type=dvbf_steps, default=None,
                    help=f"steps per method (default: the Table II budget of the maze; at most {MAX_DVBF_STEPS})")
    dx.add_argument("--methods", nargs="+", default=["mi", "random", "frontier"],
                    choices=("mi", "mi-pull", "random", "frontier"),
                    help="mi: the paper's agent; mi-pull: with the frontier pull (ours); default: mi random frontier")
    dx.add_argument("--seed", type=seed_int, default=0, help="start, noise and agent seed (default: 0)")
    dx.add_argument("--out", default="runs/dvbf-explore", help="run directory (default: runs/dvbf-explore)")
    dx.add_argument("--quiet", action="store_true")
    add_run_options(dx)
    dx.set_defaults(func=_dvbf_explore, out_dir=lambda a: Path(a.out))

    from .study.runner import build_parser as study_arguments

    r = sub.add_parser("reproduce", help="re-run a study of the paper (tables and figures beside the published ones)")
    study_arguments(r)
    r.set_defaults(func=_reproduce)
    return p


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    prog = f"cogmap {args.command}" + (f" {args.drone_command}" if args.command == "drone" else "")
    try:
        import_plugins(args.plugin)
        if hasattr(args, "out_dir"):  # a run command: run directory checks and a wall-clock limit
            return run_command(args, prog, args.out_dir(args))
        return args.func(args)
    except KeyboardInterrupt:
        if args.debug:
            raise
        print(f"{prog}: interrupted", file=sys.stderr)
        return 130
    except Exception as err:  # noqa: BLE001 - every error becomes one line unless --debug
        if args.debug:
            raise
        print(f"{prog}: error: {one_line(err)}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())

"""Run an AIMAPP agent in a pybullet room and write a run directory.

The run directory holds ``run.json`` (config, seed, odometry noise, versions, commit), the model
(``model.npz`` + ``model.json``), the places' anchors for drift correction (``anchors.npz``),
the cognitive map (``map.graphml``), the observations (``observations/*.png``),
``trajectory.csv`` (true pose, odometry, believed pose in the corrected frame, state, action per
step), ``metrics.json`` and the plots ``map.png`` and ``coverage.png``.
"""

from __future__ import annotations

import csv
import json
import warnings
from dataclasses import asdict
from pathlib import Path

import numpy as np

from cogmap.agent.aimapp import AIMAPPAgent
from cogmap.agent.config import AgentConfig
from cogmap.agent.exploration_end import Done
from cogmap.agent.policy import AgentPolicy, sense  # noqa: F401  (sense: kept importable from here)
from cogmap.harness import Episode, coverage_tracker, run_episode
from cogmap.metrics import coverage_efficiency, nauc, rmse

TRAJ_FIELDS = [
    "step", "true_x", "true_y", "true_yaw", "odom_x", "odom_y", "odom_yaw", "belief_x", "belief_y", "belief_yaw",
    "state", "action", "mode", "missing", "moved", "num_states", "num_obs", "coverage", "distance", "decision_ms",
]


def layout_name(env: str) -> str:
    """Accept a layout name (``mini_warehouse``), a registered id (``cogmap/MiniWarehouse-v0``), a
    procedural building (``building:office:3``, see :func:`building_spec`) or a layout file
    (``building.json`` or a ``plan.png``; returned as an absolute path, so a run's ``run.json`` finds
    it again from anywhere).

    Parameters
    ----------
    env : str
        What the user typed after ``--env``.

    Returns
    -------
    str
        The layout name, the ``building:KIND:SEED`` string, or the absolute path of the file.

    Raises
    ------
    ValueError
        For anything else: the id of an environment another command runs (the message names the
        command), a file of a type that is not read (the message names the types that are), or an
        unknown name (the message lists what is accepted).
    """
    from cogmap.envs.layout_file import is_layout_file
    from cogmap.envs.layouts import LAYOUTS
    from cogmap.envs.registry import LAYOUT_IDS

    if not isinstance(env, str) or not env:
        raise ValueError(f"env: expected a layout name, registered id, building:KIND:SEED or layout file, got {env!r}")
    if env in LAYOUT_IDS:
        return LAYOUT_IDS[env]
    if env in LAYOUTS:
        return env
    if is_layout_file(env):
        return str(Path(env).resolve())
    if env.startswith("building:"):
        building_spec(env)  # checked here
        return env
    if env in OTHER_COMMANDS:
        raise ValueError(f"{env} is not a room for cogmap explore: {OTHER_COMMANDS[env]}")
    if Path(env).suffix or Path(env).exists():
        raise ValueError(f"{env}: not a layout file cogmap reads; --env reads a .json building or a .png plan "
                         f"(see docs/tutorial-aimapp.md)")
    raise ValueError(f"unknown environment {env!r}; use one of {sorted(LAYOUTS)}, {sorted(LAYOUT_IDS)}, "
                     f"building:KIND:SEED or a layout file (.json building or .png plan)")


#: registered ids of environments that other commands run, and what to run instead
OTHER_COMMANDS = {
    "cogmap/DroneField-v0": "it is the drone's 3D obstacle field; fly it with 'cogmap drone fly' "
                            "(or gymnasium.make('cogmap/DroneField-v0'))",
    "cogmap/LidarMaze-v0": "it is the DVBF-LM LiDAR maze; run it with 'cogmap dvbf slam', 'cogmap dvbf navigate' "
                           "or 'cogmap dvbf explore' (--maze SEED)",
    "cogmap/GridWorld-v0": "it is the discrete grid world; use it from Python with "
                           "gymnasium.make('cogmap/GridWorld-v0')",
}


def building_spec(env: str) -> tuple[str, int]:
    """``building:KIND:SEED`` (a procedural building, :mod:`cogmap.envs.buildings`) as (kind, seed).

    Parameters
    ----------
    env : str
        ``"building:KIND:SEED"``.

    Returns
    -------
    kind : str
        The building kind (corridor, office, L, T, U, hall).
    seed : int
        The building seed."""
    from cogmap.envs.buildings import KINDS

    parts = env.split(":")
    if len(parts) != 3 or parts[1] not in KINDS or not parts[2].isdigit():
        raise ValueError(f"expected building:KIND:SEED with KIND one of {list(KINDS)} and SEED an integer >= 0, "
                         f"got {env!r}")
    return parts[1], int(parts[2])


def resolve_layout(env: str, check_space: bool = True):
    """The :class:`~cogmap.envs.layouts.Layout` that ``env`` names (see :func:`layout_name`).

    Parameters
    ----------
    env : str
        A layout name, registered id, ``building:KIND:SEED`` or layout file.
    check_space : bool, optional
        For a layout file: also run the checks that rasterise the building (free space, starts;
        :func:`cogmap.envs.layout_file.check_layout`); False reads and bounds every entry only.

    Returns
    -------
    Layout
        The layout (a layout file is loaded and checked)."""
    from cogmap.envs import make_layout
    from cogmap.envs.layout_file import is_layout_file, load_layout

    name = layout_name(env)
    if is_layout_file(name):
        return load_layout(name, check_space=check_space)
    if name.startswith("building:"):
        kind, seed = building_spec(name)
        return make_layout("building", seed, kind=kind)
    return make_layout(name)


def check_env(env: str) -> None:
    """The quick check of ``env`` before a run starts (``cogmap explore`` runs it before the
    supervised child): the name resolves, and a layout file is read with every entry checked and
    bounded (:data:`~cogmap.envs.layout_file.MAX_EXTENT_M`, ...). The checks that rasterise the
    building (free space, starts) run in the run itself, under its time limit.

    Parameters
    ----------
    env : str
        As for :func:`layout_name`.

    Raises
    ------
    ValueError
        From :func:`layout_name` or :class:`~cogmap.envs.layout_file.LayoutFileError`.
    """
    from cogmap.envs.layout_file import is_layout_file

    if is_layout_file(layout_name(env)):
        resolve_layout(env, check_space=False)


def default_config(env: str) -> AgentConfig:
    """Influence radius 1 m in small rooms and the house (doorways), 2 m in large open ones (Table 6).

    Parameters
    ----------
    env : str
        The environment, as for :func:`layout_name`.

    Returns
    -------
    AgentConfig
        The agent's configuration for that environment."""
    large = layout_name(env) in ("large_warehouse", "parking_lot", "aisle_warehouse")
    return AgentConfig(influence_radius=2.0 if large else 1.0)


def make_sim(env: str, cfg: AgentConfig, seed: int, noise=None, layout=None):
    """The room, with the start pose chosen by the seed: every seed starts somewhere else, as in
    the paper's protocol (the layout's start poses first, then poses sampled from the free
    space; :func:`cogmap.starts.seed_start`).

    Parameters
    ----------
    env : str
        The environment, as for :func:`layout_name`.
    cfg : AgentConfig
        Sets the step length (the influence radius) and the obstacle margin of the simulator.
    seed : int
        Start pose and noise seed.
    noise : OdometryNoise, optional
        Odometry drift; default none.
    layout : Layout, optional
        ``resolve_layout(env)`` when the caller has it already (a layout file is then not read and
        validated twice).

    Returns
    -------
    NavSim
        The simulator (the caller closes it)."""
    from cogmap.envs import NavSim, OdometryNoise, SimConfig

    from .starts import seed_start

    layout = layout if layout is not None else resolve_layout(env)
    sim_cfg = SimConfig(step_length=cfg.influence_radius, obstacle_margin=cfg.obstacle_margin,
                        noise=noise or OdometryNoise())
    return NavSim(layout, sim_cfg, seed=seed, start=seed_start(layout, seed, sim_cfg.robot_radius))


def run_agent(sim, agent: AIMAPPAgent, steps: int, progress: bool = True, episode: Episode | None = None,
              on_step=None, stop=None, desc: str = "explore") -> Episode:
    """Drive ``agent`` in ``sim`` for ``steps`` decisions, tracking LiDAR coverage (the
    harness's :func:`cogmap.harness.run_episode`; ``on_step`` and ``stop`` get the agent's
    :class:`Decision`).

    Parameters
    ----------
    sim : NavSim
        The simulator.
    agent : AIMAPPAgent
        The agent.
    steps : int
        Largest number of decisions.
    progress : bool, optional
        Show a progress bar, default True.
    episode : Episode, optional
        An earlier episode to continue.
    on_step, stop : callable, optional
        Called with each decision (``stop`` returns whether to end).
    desc : str, optional
        Progress-bar label.

    Returns
    -------
    Episode
        The episode record.
    """
    return run_episode(sim, AgentPolicy(agent), steps, progress=progress, episode=episode, on_step=on_step,
                       stop=stop, desc=desc)


def episode_metrics(sim, ep: Episode) -> dict:
    """The metrics of a run as ``metrics.json`` holds them.

    Parameters
    ----------
    sim : NavSim
        The simulator the episode ran in (for the coverage tracker and the grid).
    ep : Episode
        The episode.

    Returns
    -------
    dict
        ``steps``, ``coverage`` (fraction), ``area_covered_m2``, ``free_area_m2``, ``distance_m``,
        ``coverage_efficiency`` (m2/m), ``nauc``, ``num_states``, ``num_observations``,
        ``decision_ms_mean`` / ``_p95``, ``rmse_belief_m`` / ``rmse_odometry_m`` (m, against the
        true path) and ``failed_moves``.
    """
    rows = ep.rows
    truth = np.array([[r["true_x"], r["true_y"]] for r in rows])
    odom = np.array([[r["odom_x"], r["odom_y"]] for r in rows])
    belief = np.array([[r["belief_x"], r["belief_y"]] for r in rows])
    ok = np.all(np.isfinite(belief), axis=1) & np.all(np.isfinite(odom), axis=1)
    dist = ep.distance[-1]
    tracker = coverage_tracker(sim)
    area = tracker.area
    return {
        "steps": len(rows),
        "coverage": ep.coverage[-1],
        "area_covered_m2": area,
        "free_area_m2": tracker.total * sim.grid.resolution**2,
        "distance_m": dist,
        "coverage_efficiency": coverage_efficiency(area, dist),
        "nauc": nauc(ep.distance, ep.coverage, budget=max(dist, 1e-9)),
        "num_states": ep.num_states[-1] if ep.num_states else 0,
        "num_observations": rows[-1]["num_obs"] if rows else 0,
        "decision_ms_mean": float(np.mean(ep.decision_ms)) if ep.decision_ms else 0.0,
        "decision_ms_p95": float(np.percentile(ep.decision_ms, 95)) if ep.decision_ms else 0.0,
        "rmse_belief_m": rmse(belief[ok], truth[ok]) if ok.any() else None,
        "rmse_odometry_m": rmse(odom[ok], truth[ok]) if ok.any() else None,
        "failed_moves": int(sum(1 for r in rows if r["moved"] is False)),
    }


def write_run(out: Path, sim, agent: AIMAPPAgent, ep: Episode, metrics: dict, title: str | None = None) -> None:
    """Write a run directory: the model (``cogmap.genmodel.io``, no pickle), the place anchors, the
    map as GraphML, the stored panoramas, ``trajectory.csv``, ``metrics.json`` and the map and
    coverage plots.

    Parameters
    ----------
    out : Path
        The run directory (created if missing).
    sim : NavSim
        The simulator of the run (floor plan for the plots).
    agent : AIMAPPAgent
        The agent after the run.
    ep : Episode
        The episode.
    metrics : dict
        What :func:`episode_metrics` (and the end rule) returned.
    title : str, optional
        Title of the map plot.
    """
    from cogmap.agent.correction import save_anchors
    from cogmap.genmodel.graph import write_graphml
    from cogmap.genmodel.io import save

    from . import plots

    out.mkdir(parents=True, exist_ok=True)
    save(agent.model, out / "model")
    if agent.memory.anchors:  # views and scans that drift correction compares with (cogmap.agent.correction)
        save_anchors(out / "anchors.npz", agent.memory.anchors)
    write_graphml(agent.model, out / "map.graphml")
    obs_dir = out / "observations"
    obs_dir.mkdir(exist_ok=True)
    import cv2

    for i, img in enumerate(agent.encoder.images):
        cv2.imwrite(str(obs_dir / f"{i:04d}.png"), cv2.cvtColor(np.asarray(img), cv2.COLOR_RGB2BGR))
    with open(out / "trajectory.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=TRAJ_FIELDS)
        w.writeheader()
        w.writerows(ep.rows)
    (out / "metrics.json").write_text(json.dumps(metrics, indent=1))
    plots.map_over_floorplan(out / "map.png", sim, agent, ep, title)
    plots.coverage_curve(out / "coverage.png", ep)


CHECKPOINT = "checkpoint"
#: the simulator's state a checkpoint keeps (everything that changes as the robot moves)
SIM_STATE = ("pose", "odom", "rng", "step_count", "path", "odom_path", "scheduled", "faults")


def save_state(out: Path, sim, agent: AIMAPPAgent, done: Done, ep: Episode, moved, distance: float) -> Path:
    """Checkpoint the exploration after a decision (:mod:`cogmap.checkpoint`: the model in its own
    format, the rest as JSON + npz).

    Parameters
    ----------
    out : Path
        The run directory (the checkpoint goes to ``out/checkpoint``).
    sim : NavSim
        The simulator (its pose, odometry, generator and fault schedule are kept).
    agent : AIMAPPAgent
        The agent.
    done : Done
        The end rule and its counters.
    ep : Episode
        The episode so far.
    moved : bool or None
        Outcome of the last motion command.
    distance : float
        Distance travelled so far, metres.

    Returns
    -------
    Path
        The checkpoint directory."""
    from cogmap.checkpoint import save_checkpoint

    tracker = coverage_tracker(sim)
    return save_checkpoint(out / CHECKPOINT, {
        "agent": agent, "done": done, "episode": ep, "moved": moved, "distance": float(distance),
        "coverage_seen": tracker.seen, "sim": {k: getattr(sim, k) for k in SIM_STATE},
    })


def restore_state(path: Path, sim) -> tuple[AIMAPPAgent, Done, Episode, bool | None, float]:
    """Put ``sim`` (built afresh for the same layout and seed) back where the checkpoint left it and
    return the agent, the end rule, the episode so far, the last motion outcome and the distance.

    Parameters
    ----------
    path : Path
        The checkpoint directory.
    sim : NavSim
        A simulator built afresh for the same layout and seed.

    Returns
    -------
    agent : AIMAPPAgent
    done : Done
    episode : Episode
    moved : bool or None
    distance : float
        Metres travelled so far."""
    from cogmap.checkpoint import load_checkpoint

    st = load_checkpoint(path)
    for k, v in st["sim"].items():
        setattr(sim, k, v)
    sim.scene.set_robot(sim.pose)
    sim._cache = {}
    coverage_tracker(sim).seen = st["coverage_seen"]
    return st["agent"], st["done"], st["episode"], st["moved"], st["distance"]


def check_settings(where: str, **settings) -> None:
    """Refuse an exploration setting of the wrong type or out of its range, naming it.

    Parameters
    ----------
    where : str
        Prefix of the message (the function, or the ``run.json`` the settings were read from).
    **settings
        Any of ``steps`` (1 .. :data:`~cogmap.argtypes.MAX_DECISIONS`), ``seed`` (0 ..
        :data:`~cogmap.argtypes.MAX_SEED`), ``patience`` (0 .. ``MAX_DECISIONS``) and
        ``checkpoint_every`` (1 .. ``MAX_DECISIONS``), integers (not bools).

    Raises
    ------
    ValueError
        ``"<where>: <field>: ..."`` naming the range and the value.
    """
    from .argtypes import MAX_DECISIONS, MAX_SEED

    ranges = {"steps": (1, MAX_DECISIONS, "MAX_DECISIONS"), "seed": (0, MAX_SEED, "MAX_SEED"),
              "patience": (0, MAX_DECISIONS, "MAX_DECISIONS"), "checkpoint_every": (1, MAX_DECISIONS, "MAX_DECISIONS")}
    for key, value in settings.items():
        lo, hi, name = ranges[key]
        if isinstance(value, bool) or not isinstance(value, int | np.integer) or not lo <= value <= hi:
            raise ValueError(f"{where}: {key}: expected an integer in {lo}..{hi} ({name}), got {_shown(value)}")


def _shown(value) -> str:
    """A value as the file holds it (JSON), else its repr."""
    try:
        return json.dumps(value)
    except (TypeError, ValueError):
        return repr(value)


def resume_state(out: Path) -> str:
    """What ``--resume`` can do with the run directory of a stopped exploration, as the end of the
    message of ``cogmap explore`` (:func:`cogmap.runguard.resume_hint`); it checks what
    :func:`resume_settings` needs.

    Parameters
    ----------
    out : pathlib.Path
        The run directory.

    Returns
    -------
    str
        ``" (--resume continues it)"`` when ``run.json`` is there (from the last checkpoint, or
        from the start without one), else why ``--resume`` cannot continue it and what to do.
    """
    if (out / "metrics.json").is_file():
        return " (it had written its results, metrics.json: --resume has nothing to continue)"
    if (out / "run.json").is_file():
        return " (--resume continues it)"
    return " (--resume cannot continue it: it stopped before writing run.json; start it again with --force)"


def resume_settings(out: Path, checkpoint_every: int = 10) -> tuple:
    """The settings of the exploration in ``out`` to resume, read from its ``run.json`` with every
    field checked (type and range) before anything is built.

    Parameters
    ----------
    out : pathlib.Path
        The run directory.
    checkpoint_every : int, optional
        Used when ``run.json`` has no ``checkpoint_every`` (runs written before it was recorded).

    Returns
    -------
    tuple
        ``(env, steps, seed, patience, checkpoint_every, config, noise)``.

    Raises
    ------
    ValueError
        When ``run.json`` is missing or unreadable, not an exploration's, the run has finished, or
        a field is missing or of the wrong type or range (``"<out>/run.json: <field>: ..."``).
    """
    from cogmap.envs import OdometryNoise

    where = f"{out}/run.json"
    try:
        manifest = json.loads((out / "run.json").read_text())
    except (OSError, ValueError):
        raise ValueError(f"{out}: no readable run.json to resume from") from None
    if not isinstance(manifest, dict):
        raise ValueError(f"{where}: expected a JSON object, got {type(manifest).__name__}")
    if manifest.get("command") != "explore":
        raise ValueError(f"{out}: not an exploration run (run.json says {manifest.get('command')!r})")
    if (out / "metrics.json").exists():
        raise ValueError(f"{out}: the run has finished (metrics.json); nothing to resume")
    for key in ("env", "steps", "seed", "patience", "config", "noise"):
        if key not in manifest:
            raise ValueError(f"{where}: missing field {key!r}")
    settings = {k: manifest[k] for k in ("steps", "seed", "patience")}
    settings["checkpoint_every"] = manifest.get("checkpoint_every", checkpoint_every)
    check_settings(where, **settings)
    env = manifest["env"]
    if not isinstance(env, str):
        raise ValueError(f"{where}: env: expected a string, got {_shown(env)}")
    try:
        layout_name(env)
    except ValueError as err:
        raise ValueError(f"{where}: env: {err}") from None
    if not isinstance(manifest["config"], dict):
        raise ValueError(f"{where}: config: expected an object of AgentConfig fields, got {_shown(manifest['config'])}")
    try:
        config = AgentConfig.from_dict(manifest["config"])
    except (TypeError, ValueError) as err:
        raise ValueError(f"{where}: config: {err}") from None
    noise = manifest["noise"]
    if not isinstance(noise, dict):
        raise ValueError(f"{where}: noise: expected an object of OdometryNoise fields, got {_shown(noise)}")
    unknown = sorted(set(noise) - {"slip", "heading_bias", "trans_std", "rot_std"})
    if unknown:
        raise ValueError(f"{where}: noise: unknown field(s) {', '.join(map(repr, unknown))}")
    try:
        noise = OdometryNoise(**noise)
    except ValueError as err:
        raise ValueError(f"{where}: noise: {err}") from None
    return (env, settings["steps"], settings["seed"], settings["patience"], settings["checkpoint_every"], config,
            noise)


def explore(env: str = "mini_warehouse", steps: int = 150, seed: int = 0, out: Path | str | None = None,
            config: AgentConfig | None = None, progress: bool = True, noise=None, patience: int = 20,
            checkpoint_every: int = 10, resume: bool = False) -> dict:
    """The main job: explore ``env`` for at most ``steps`` decisions (ending early once the agent
    has nothing left to visit for ``patience`` decisions; 0 never ends early) and write the run
    directory.

    With ``out``, the state is checkpointed to ``out/checkpoint`` every ``checkpoint_every``
    decisions (removed once the run has finished and written its files). ``resume=True`` continues
    the run in ``out`` from its last checkpoint with the settings recorded in its ``run.json`` (the
    other arguments are ignored), or from the start when it stopped before its first checkpoint.

    Parameters
    ----------
    env : str, optional
        Layout name, registered id, ``building:KIND:SEED`` or layout file; default the mini warehouse.
    steps : int, optional
        Largest number of decisions, default 150.
    seed : int, optional
        Start pose, noise and agent seed.
    out : Path or str, optional
        Run directory to write; None writes nothing.
    config : AgentConfig, optional
        The agent's configuration; default :func:`default_config` of ``env``.
    progress : bool, optional
        Show a progress bar, default True.
    noise : OdometryNoise, optional
        Odometry drift, default none.
    patience : int, optional
        Quiet decisions before the agent ends its exploration (:class:`Done`), default 20.
    checkpoint_every : int, optional
        Decisions between checkpoints when ``out`` is given, default 10.
    resume : bool, optional
        Continue the run in ``out``.

    Returns
    -------
    dict
        The run's metrics (:func:`episode_metrics` plus the end of exploration).

    Raises
    ------
    ValueError
        When ``resume`` is asked without ``out``, a setting is out of its range
        (:func:`check_settings`), or, on ``resume``, ``run.json`` is missing, not an exploration's,
        or holds a field of the wrong type or range (the message names the field).
    """
    from cogmap.envs import OdometryNoise

    from .checkpoint import CheckpointError, find_checkpoint
    from .runs import write_manifest

    if resume:
        if out is None:
            raise ValueError("resume needs the run directory (out)")
        out = Path(out)
        env, steps, seed, patience, checkpoint_every, config, noise = resume_settings(out, checkpoint_every)
    else:
        check_settings("explore", steps=steps, seed=seed, patience=patience, checkpoint_every=checkpoint_every)
    cfg = config or default_config(env)
    layout = resolve_layout(env)  # a layout file is validated here, in the run (under its time limit)
    if out is not None and not resume:
        # run.json before the work a time limit may cut, so that --resume can continue from here
        out = Path(out)
        write_manifest(out, command="explore", env=layout_name(env), steps=steps, seed=seed,
                       patience=patience, checkpoint_every=checkpoint_every, config=cfg.to_dict(),
                       noise=asdict(noise or OdometryNoise()))
    sim = make_sim(env, cfg, seed, noise, layout=layout)
    try:
        found = find_checkpoint(out / CHECKPOINT) if resume else None
        if found is not None:
            agent, done, ep, moved, distance = restore_state(found, sim)
            json_path = out / "run.json"
            manifest = json.loads(json_path.read_text())
            manifest.setdefault("resumed_at", []).append(len(ep.rows))
            json_path.write_text(json.dumps(manifest, indent=1))
        else:
            agent = AIMAPPAgent(cfg, seed=seed)
            done, ep, moved, distance = Done(agent, patience), Episode(), None, None

        failed_checkpoint: list[str] = []

        def checkpoint(ep, moved, distance):
            if len(ep.rows) % checkpoint_every == 0 and not failed_checkpoint:
                try:
                    save_state(out, sim, agent, done, ep, moved, distance)
                except CheckpointError as err:  # a state the codec cannot write: the run goes on without
                    failed_checkpoint.append(str(err))
                    warnings.warn(f"exploration checkpoints stopped (--resume will not be possible): {err}",
                                  stacklevel=2)

        ep = run_episode(sim, AgentPolicy(agent), steps - len(ep.rows), progress=progress, episode=ep, stop=done,
                         desc="explore", after_step=checkpoint if out is not None else None, moved=moved,
                         distance=distance)
        metrics = {**episode_metrics(sim, ep), **done.summary()}
        if out is not None:
            write_run(out, sim, agent, ep, metrics)
            import shutil

            shutil.rmtree(out / CHECKPOINT, ignore_errors=True)
        return metrics
    finally:
        sim.close()

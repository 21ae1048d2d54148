"""Goal reaching with a model learnt during exploration (section 4.4).

The goal is an image (or a stored observation id). It is recognised by the encoder, and the
agent plans in goal mode: preference weight 10 on the goal observation, the inductive term
toward the states that produced it, and the collision term. The run stops when the agent
confidently observes the goal.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from cogmap.agent.aimapp import AIMAPPAgent
from cogmap.agent.config import AgentConfig
from cogmap.agent.correction import load_anchors
from cogmap.agent.encoder import make_encoder

from .explore import episode_metrics, make_sim, run_agent, write_run


def astar_length(grid, start_xy, goal_xy, robot_radius: float) -> float:
    """Shortest collision-free path length for a disc robot on the occupancy grid.

    The reference of the goal study's path ratio (section 4.4: executed path over the A* optimum).

    Parameters
    ----------
    grid : cogmap.envs.occupancy.OccupancyGrid
        The world's occupancy grid (ground truth).
    start_xy, goal_xy : array_like
        ``(2,)`` (or longer: only x, y are read) world positions, metres.
    robot_radius : float
        Robot radius, metres; obstacles are inflated by 0.9 of it.

    Returns
    -------
    float
        8-connected A* path length, metres; ``inf`` when there is no path (or an end cell is
        occupied or outside the grid).
    """
    from cogmap.planning.astar import astar_grid

    blocked = grid.inflated(robot_radius * 0.9)
    s, g = grid.world_to_cell(np.asarray(start_xy)[:2]), grid.world_to_cell(np.asarray(goal_xy)[:2])
    _, length = astar_grid(blocked, tuple(s), tuple(g), grid.resolution)
    return float(length)


def exploration_manifest(run: Path) -> dict:
    """The ``run.json`` of an exploration run, read and checked before anything is built from it.

    Its ``"command"`` field is read first, so another kind of run directory (``cogmap drone fly``,
    ``cogmap dvbf ...``, a goal run) is named as such instead of failing on a field it lacks.

    Parameters
    ----------
    run : pathlib.Path
        The run directory.

    Returns
    -------
    dict
        The manifest.

    Raises
    ------
    FileNotFoundError
        When ``run/run.json`` does not exist.
    ValueError
        ``"DIR is a <command> run; goal needs an exploration run (cogmap explore)"``, or a
        manifest that is not JSON, not an object, or lacks ``config``, ``env`` or ``seed``.
    """
    path = Path(run) / "run.json"
    try:
        manifest = json.loads(path.read_text())
    except (UnicodeDecodeError, json.JSONDecodeError) as err:
        raise ValueError(f"{path}: not valid JSON ({err})") from None
    if not isinstance(manifest, dict):
        raise ValueError(f"{path}: expected a JSON object, got {type(manifest).__name__}")
    command = manifest.get("command")
    if command != "explore":
        what = f"a {command} run" if isinstance(command, str) and command else \
            "not an exploration run (its run.json names no command)"
        raise ValueError(f"{run} is {what}; goal needs an exploration run (cogmap explore)")
    for key, kind, name in (("config", dict, "an object"), ("env", str, "a string"), ("seed", int, "an integer")):
        if not isinstance(manifest.get(key), kind):
            raise ValueError(f"{path}: field {key!r}: expected {name}, got {json.dumps(manifest.get(key))}")
    return manifest


def load_agent(run: Path, seed: int = 0) -> tuple[AIMAPPAgent, dict]:
    """Rebuild an agent (model, observations, config) from a run directory.

    Reads ``run.json`` (the config), the observation images of ``observations/`` (added to a
    fresh encoder of the run's kind, in file order), ``model/`` and, when present,
    ``anchors.npz`` (the drift-correction anchors).

    Parameters
    ----------
    run : pathlib.Path
        Run directory written by ``cogmap explore`` (:func:`cogmap.explore.write_run`).
    seed : int, optional
        Seed of the rebuilt agent's RNG, default 0.

    Returns
    -------
    agent : cogmap.agent.aimapp.AIMAPPAgent
        The agent with the run's config, encoder, model and anchors (beliefs not set).
    manifest : dict
        The run's ``run.json``.

    Raises
    ------
    ValueError
        When ``run`` is not an exploration run (:func:`exploration_manifest`), the run's encoder
        has no ``add(image)`` method (register custom encoders before loading), or the number of
        observation images differs from the model's outcomes.
    """
    import cv2

    from cogmap.genmodel.io import load

    run = Path(run)
    manifest = exploration_manifest(run)
    cfg = AgentConfig.from_dict(manifest["config"])
    encoder = make_encoder(cfg.encoder, cfg)  # the run's encoder, by name (register yours before loading)
    if not hasattr(encoder, "add"):
        raise ValueError(f"{run}: encoder '{cfg.encoder}' has no add(image) method to restore the run's observations")
    for png in sorted((run / "observations").glob("*.png")):
        encoder.add(cv2.cvtColor(cv2.imread(str(png)), cv2.COLOR_BGR2RGB))
    model = load(run / "model")
    if len(encoder.images) != model.num_obs[0]:
        raise ValueError(f"{run}: {len(encoder.images)} observation images for {model.num_obs[0]} model outcomes")
    agent = AIMAPPAgent(cfg, encoder=encoder, seed=seed, model=model)
    if (run / "anchors.npz").exists():
        agent.memory.anchors.update(load_anchors(run / "anchors.npz"))
    return agent, manifest


def goal_observation(agent: AIMAPPAgent, image: np.ndarray) -> int:
    """Id of the stored observation matching ``image``.

    Parameters
    ----------
    agent : cogmap.agent.aimapp.AIMAPPAgent
        An agent whose encoder holds the observations (e.g. from :func:`load_agent`).
    image : numpy.ndarray
        Goal panorama, ``(H, W, 3)`` uint8 RGB, as the agent's encoder takes it.

    Returns
    -------
    int
        The observation id the encoder matches best.

    Raises
    ------
    ValueError
        When no observation matches, or the best score is below ``agent.cfg.ssim_threshold``
        (Table 6).
    """
    best, score = agent.encoder.match(image)
    if best < 0 or score < agent.cfg.ssim_threshold:
        raise ValueError(f"goal image not recognised (best SSIM {score:.2f} < {agent.cfg.ssim_threshold})")
    return best


def pursue(sim, agent: AIMAPPAgent, goal_obs: int, steps: int, progress: bool = True):
    """Run goal mode from the robot's current place until the goal is observed (section 4.4).

    Parameters
    ----------
    sim : cogmap.envs.NavSim
        The simulator, with the robot where the goal run starts.
    agent : cogmap.agent.aimapp.AIMAPPAgent
        A localised agent with a learnt model (:meth:`AIMAPPAgent.localise_at`).
    goal_obs : int
        Observation id to reach (set as the agent's goal).
    steps : int
        Largest number of decisions.
    progress : bool, optional
        Show a progress bar, default True.

    Returns
    -------
    episode : cogmap.harness.Episode
        The run's record.
    summary : dict
        ``reached`` (the agent confidently observes the goal), ``steps``, ``executed_m`` (true
        distance driven, metres), ``astar_m`` (:func:`astar_length` from the start to where the
        robot stopped, metres), ``path_ratio`` (executed / A*, None when the A* length is 0 or
        infinite) and ``goal_obs``.
    """
    agent.set_goal(goal_obs)
    start = sim.true_pose()[:2].copy()
    ep = run_agent(sim, agent, steps, progress, stop=lambda d: agent.at_goal, desc="goal")
    end = sim.true_pose()[:2]
    executed = ep.distance[-1]
    optimal = astar_length(sim.grid, start, end, sim.config.robot_radius)
    summary = {
        "reached": bool(agent.at_goal),
        "steps": len(ep.rows),
        "executed_m": executed,
        "astar_m": optimal,
        "path_ratio": executed / optimal if optimal > 0 and np.isfinite(optimal) else None,
        "goal_obs": int(goal_obs),
    }
    return ep, summary


def reach_goal(run: Path, goal_image: str | None = None, goal_obs: int | None = None, steps: int = 60,
               seed: int = 0, out: Path | None = None, progress: bool = True) -> dict:
    """``cogmap goal``: start where the exploration started, knowing it (section 4.1 protocol).

    Rebuilds the agent from ``run`` (:func:`load_agent`), recreates the run's world with its seed
    and odometry noise, localises the agent at the start pose, runs :func:`pursue` and writes a
    run directory (manifest, model, trajectory, figures) to ``out``.

    Parameters
    ----------
    run : pathlib.Path
        Exploration run directory.
    goal_image : str or None, optional
        Path of the goal image; recognised with :func:`goal_observation`.
    goal_obs : int or None, optional
        Observation id of the goal, used when ``goal_image`` is None. Give one of the two.
    steps : int, optional
        Largest number of decisions, default 60.
    seed : int, optional
        Seed of the agent's RNG, default 0 (the world uses the run's own seed).
    out : pathlib.Path or None, optional
        Output directory, default ``run / "goal"``.
    progress : bool, optional
        Show a progress bar, default True.

    Returns
    -------
    dict
        The episode metrics (:func:`cogmap.explore.episode_metrics`: coverage, distance_m,
        decision times, ...) merged with the :func:`pursue` summary (reached, executed_m,
        astar_m, path_ratio, ...).

    Raises
    ------
    ValueError
        When the goal image cannot be read or is not recognised, the goal id is unknown, or the
        run cannot be rebuilt (see :func:`load_agent`).
    """
    import cv2

    from .runs import write_manifest

    agent, manifest = load_agent(run, seed)
    if goal_image is not None:
        img = cv2.imread(str(goal_image))
        if img is None:
            raise ValueError(f"cannot read goal image {goal_image}")
        goal_obs = goal_observation(agent, cv2.cvtColor(img, cv2.COLOR_BGR2RGB))
    from cogmap.envs import OdometryNoise

    noise = OdometryNoise(**manifest["noise"]) if manifest.get("noise") else None  # same drift as the exploration
    sim = make_sim(manifest["env"], agent.cfg, manifest["seed"], noise)
    try:
        agent.localise_at(sim.odometry())
        out = Path(out) if out is not None else Path(run) / "goal"
        write_manifest(out, command="goal", run=str(run), goal_obs=goal_obs, steps=steps, seed=seed)
        ep, summary = pursue(sim, agent, goal_obs, steps, progress)
        metrics = {**episode_metrics(sim, ep), **summary}
        verdict = "reached" if metrics["reached"] else "not reached"
        ratio = f", {metrics['path_ratio']:.2f}x A*" if metrics["path_ratio"] else ""
        title = f"{sim.layout.name}: goal {verdict} after {metrics['executed_m']:.1f} m{ratio}"
        write_run(out, sim, agent, ep, metrics, title)
        return metrics
    finally:
        sim.close()

"""Exploration of a LiDAR maze with DVBF-LM (paper Section VI, Algorithm 1) and two baselines.

* ``mi``: the DVBF-LM agent (``mi-pull``: the same with the frontier pull below). It learns the map
  online while it moves (:class:`~cogmap.inference.online_slam.OnlineSLAM`,
  20 particles, ELBO steps after every ``train_every`` steps; emission pretrained on a first maze and
  frozen, as in ``cogmap dvbf slam``). Every ``replan_every`` steps it builds the obstacle penalty from
  its own map, generates candidate control sequences, scores them by ``I(x_1:T; M)``
  (:mod:`cogmap.planning.mi_exploration`) and executes the first ``replan_every`` controls of the best.
* ``random``: a random walk: each step a uniform turn in ``[-max_turn, max_turn]`` and a full step;
  after a wall stopped it, a uniform turn in ``[-pi, pi]``.
* ``frontier``: a frontier explorer on an occupancy grid built from the **true** LiDAR returns at the
  **true** poses (a privileged baseline: no localisation error), cells of a quarter corridor width;
  it walks the shortest 4-connected path through known-free cells to the nearest frontier cell
  (known free, next to unknown) and re-plans when it arrives, every ``replan_every`` steps or when a
  wall stops it (marking the cell ahead occupied first, so the new path goes around the wall); with no
  frontier left it walks randomly.

Five choices of ours keep the ``mi`` agent moving (measured on moderate-small, seed 0, 300 steps: it
covered 0.083 of the tiles on a path of 0.26 before them, 0.500 on a path of 2.34 after, the random
walk 0.278 on 2.70):

* a predicted collision is a rise of the obstacle penalty above its value at the start
  (:func:`~cogmap.planning.mi_exploration.truncate_at_collision`): beside a wall, or in a corridor a few
  histogram cells wide, the penalty at the start is already high and an absolute level cut every
  candidate at its first step, so the agent stood for good;
* the current scan also cuts candidates where they would meet a wall it shows
  (:func:`~cogmap.planning.mi_exploration.scan_free_steps`), which the penalty cannot see right after a
  bump, when the agent stands on its peak;
* the MI argmax runs over the candidates with the longest free prefix (``MIConfig.feasible_only``):
  standing still, as a cut candidate does, scores a high ``I(x_1:T; M)`` (repeated scans of one place,
  no pose diffusion) without exploring;
* candidates move at full speed and only their turns are optimised (``MIConfig.steer_only``, on in
  :data:`STUDY_MI`): otherwise the optimiser also avoids walls by slowing down, and slow candidates win;
* after a bump the agent re-plans at once instead of standing until the next filter chunk.

A sixth is off by default and on in method ``mi-pull`` (:func:`method_config`): a **frontier pull**
(``MIConfig.pull_below``). The MI score sees 50 steps ahead; once the maze within that reach is known,
every candidate scores near zero and nothing draws the agent to the unexplored parts of a winding maze
(on moderate-small, seed 1, it went back and forth through the left half for 2,000 steps). When the best
candidate scores below ``pull_below`` nats, the agent instead follows the cheapest path on a grid of what
it has itself sensed (its estimated poses and the scans it received there,
:mod:`cogmap.planning.frontier_pull`) to the nearest frontier of that grid, cut where the path would
enter a wall cell or its neighbour.

All three move with the same control bounds (turn at most 0.35 rad, step at most 0.01 per time step,
actuation noise of ``cogmap dvbf slam``) from the same seeded start. The exploration ratio is measured
on the true positions over the Table II tiles (:func:`cogmap.envs.maze.exploration_ratio`); the
information gain is ``KL(q(M) || p(M))`` of the agent's map (Appendix D), for the baselines when
``learn_map`` is on (the same online SLAM fed with their data).
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass, field

import numpy as np

from cogmap.envs.maze import Maze
from cogmap.envs.maze_episode import ExploreResult, MazeEpisode, MazePilot
from cogmap.envs.maze_poses import start_pose
from cogmap.envs.maze_sim import ROBOT_NOISE, MazeSim
from cogmap.genmodel.dvbf import maze_config
from cogmap.planning.maze_explorers import Frontier, RandomWalk
from cogmap.planning.mi_exploration import MIConfig
from cogmap.planning.mi_planner import MIPlanner

METHODS = ("mi", "random", "frontier")


@dataclass(frozen=True)
class ExploreConfig:
    """One exploration run. ``mi``: planning settings (the paper's defaults are heavy: see
    :data:`STUDY_MI` for the ones the study uses); ``replan_every``: steps executed per plan (a
    multiple of ``train_every``); ``train_iters``/``train_every``: ELBO steps per filtered chunk;
    ``learn_map``: run the online SLAM for the baselines too (for their information gain);
    ``penalty_from``: end points of the obstacle histogram from the scans ``"predicted"`` by the map mean
    at the estimated poses (Algorithm 2, line 6) or from the ``"observed"`` scans at the estimated poses
    (default: early in a run the learnt map predicts walls poorly and the agent ran into them);
    ``curve_every``: spacing of the recorded curves.

    Attributes
    ----------
    method : str
        ``"mi"``, ``"random"`` or ``"frontier"``.
    mi : MIConfig
        Planning settings of the ``mi`` agent (Algorithms 1-2, Appendix E).
    replan_every : int
        Steps executed per plan, a positive multiple of ``train_every``.
    train_every : int
        Steps per filtered chunk of the online SLAM.
    train_iters : int
        ELBO steps after each chunk.
    learn_map : bool
        Run the online SLAM for the baselines too.
    penalty_from : str
        ``"observed"`` or ``"predicted"`` scans for the obstacle histogram.
    max_turn : float
        Largest turn per step, in radians.
    max_step : float
        Largest forward step, in maze units.
    curve_every : int
        Steps between two points of the ratio curve (the information gain every ten times that).
    seed : int
        Seed of the start pose, the actuation noise and the agent.

    Raises
    ------
    ValueError
        For an unknown ``method`` or a ``replan_every`` that is not a positive multiple of ``train_every``.
    """

    method: str = "mi"
    mi: MIConfig = field(default_factory=MIConfig)
    replan_every: int = 50
    train_every: int = 10
    train_iters: int = 5
    learn_map: bool = False
    penalty_from: str = "observed"
    max_turn: float = 0.35
    max_step: float = 0.01
    curve_every: int = 10
    seed: int = 0

    def __post_init__(self):
        if self.method not in METHODS:
            raise ValueError(f"ExploreConfig: method must be one of {METHODS}, got {self.method!r}")
        if self.replan_every < 1 or self.replan_every % self.train_every:
            raise ValueError(f"ExploreConfig: replan_every ({self.replan_every}) must be a positive multiple of "
                             f"train_every ({self.train_every})")

    def to_json(self) -> dict:
        """The settings as a JSON-ready dict (``mi`` nested as a dict).

        Returns
        -------
        dict
            Field name -> value. The frontier pull's settings are left out while it is off
            (``mi.pull_below`` None): they do nothing then, and study keys made before it existed stay valid.
        """
        out = asdict(self)
        if self.mi.pull_below is None:
            for k in ("pull_below", "pull_cell", "pull_hit_min", "pull_min_crossed"):
                out["mi"].pop(k)
        return out


#: planning settings of the study (much lighter than the paper's F = 40, L = 30, M = 40, K = 100)
STUDY_MI = MIConfig(horizon=50, n_candidates=12, n_marginal=24, n_maps=6, n_per_map=12, opt_iters=150,
                    obs_every=10, dim=4, pose_samples=2, steer_only=True)
#: ``MIConfig.pull_below`` of the agent with the frontier pull (method ``mi-pull``), nats of the study's estimator
PULL_BELOW = 1.0
#: every method a run can name: the DVBF-LM agent as the paper runs it, with the frontier pull, and the baselines
RUN_METHODS = ("mi", "mi-pull", "random", "frontier")


def method_config(method: str, **fields) -> ExploreConfig:
    """The :class:`ExploreConfig` of a run method: ``"mi-pull"`` is the ``mi`` agent with ``mi.pull_below =``
    :data:`PULL_BELOW` (on top of ``fields["mi"]``, default :data:`STUDY_MI`); the others name their method.

    Parameters
    ----------
    method : str
        One of :data:`RUN_METHODS`.
    **fields
        Other :class:`ExploreConfig` fields.

    Returns
    -------
    ExploreConfig

    Raises
    ------
    ValueError
        For an unknown method.
    """
    import dataclasses

    if method not in RUN_METHODS:
        raise ValueError(f"method must be one of {RUN_METHODS}, got {method!r}")
    if method != "mi-pull":
        return ExploreConfig(method=method, **fields)
    mi = dataclasses.replace(fields.pop("mi", STUDY_MI), pull_below=PULL_BELOW)
    return ExploreConfig(method="mi", mi=mi, **fields)


class MIAgent:
    """The DVBF-LM agent's controls (Algorithm 1): the first controls of the best candidate of each
    planning call on its own online SLAM, re-planned when they are used up or a wall stopped it.

    Parameters
    ----------
    planner : MIPlanner
        The planning call.
    slam : OnlineSLAM
        The agent's map and pose posterior (advanced by the episode, flushed here before a plan).
    cfg : ExploreConfig
        ``replan_every`` and ``train_every``.
    rng : numpy.random.Generator
        The candidates' generator.

    Attributes
    ----------
    plan_seconds : list of float
        Wall clock of each planning call.
    pulled : int
        Planning calls in which the frontier pull chose the controls.
    """

    def __init__(self, planner: MIPlanner, slam, cfg: ExploreConfig, rng: np.random.Generator):
        self.planner, self.slam, self.cfg, self.rng = planner, slam, cfg, rng
        self.queue: list[np.ndarray] = []
        self.plan_seconds: list[float] = []
        self.pulled = 0

    def act(self, pose, scan, blocked: bool) -> np.ndarray:
        """The next control (the same call as the baselines').

        Parameters
        ----------
        pose : numpy.ndarray, shape (3,)
            True pose (unused: the agent plans from its own posterior).
        scan : numpy.ndarray, shape (n_beams,)
            Current scan (unused here: the SLAM has it).
        blocked : bool
            Whether a wall stopped the last step: the plan ran into it, re-plan from here at once.

        Returns
        -------
        numpy.ndarray, shape (2,)
            ``(turn in rad, forward in maze units)``.
        """
        cfg = self.cfg
        if blocked:
            self.queue = []
        if not self.queue:
            self.slam.flush()  # plan from the latest pose posterior
            t0 = time.perf_counter()
            u_best, info = self.planner.plan(self.slam, self.rng)
            self.plan_seconds.append(time.perf_counter() - t0)
            self.pulled += int(info["pulled"])
            # execute up to the predicted collision, rounded up to whole filter chunks (standing after it)
            free = int(info["free_steps"][info["best"]])
            n = min(cfg.replan_every, cfg.train_every * max(1, -(-free // cfg.train_every)))
            self.queue = list(u_best[:n])
        return self.queue.pop(0)


def cache_dir():
    """Where the pretrained emission is kept between runs (``$XDG_CACHE_HOME/cogmap``, else ``~/.cache/cogmap``).

    Returns
    -------
    pathlib.Path
        The directory (not created here).
    """
    import os
    from pathlib import Path

    return Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "cogmap"


def pretrained_emission(cache_dir=None, seed: int = 0, steps: int = 2000, iters: int = 1500):
    """The emission network trained with known poses on a traversal of maze 0 (moderate / medium), as
    ``cogmap dvbf slam`` does; cached in ``cache_dir`` (npz + JSON) when given, since every run of a
    study uses the same one.

    Parameters
    ----------
    cache_dir : path, optional
        Cache directory; the network is stored under ``emission-maze0-s{seed}-{steps}-{iters}``.
    seed : int
        Seed of the traversal (``seed + 1000``) and of the training.
    steps : int
        Length of the traversal.
    iters : int
        ELBO steps of the training.

    Returns
    -------
    emission
        The trained emission network (from the cache if present).
    """
    from pathlib import Path

    from cogmap.envs.maze import make_maze
    from cogmap.envs.maze_traversal import traverse
    from cogmap.inference.dvbf_files import load_params, save_emission_once
    from cogmap.inference.online_slam import pretrain_emission

    cache = None
    if cache_dir is not None:
        cache = Path(cache_dir) / f"emission-maze0-s{seed}-{steps}-{iters}"
        if (cache / "model.json").is_file():
            return load_params(cache)[0].emission
    maze = make_maze(0)
    tr = traverse(maze, steps, seed=seed + 1000, noise=ROBOT_NOISE)
    model = maze_config(maze.size, maze.map_side, ROBOT_NOISE.rot_std)
    emission, _ = pretrain_emission(tr.poses, tr.scans, model, iters=iters, seed=seed)
    if cache is not None:
        save_emission_once(emission, model, cache)
    return emission


def explore(maze: Maze, steps: int, cfg: ExploreConfig, emission=None, progress: bool = False,
            desc: str | None = None) -> ExploreResult:
    """Run one exploration of ``steps`` time steps (the start pose counts as step 0).

    Parameters
    ----------
    maze : Maze
        The maze to explore.
    steps : int
        Time steps, ``>= 2``.
    cfg : ExploreConfig
        Method and settings.
    emission : optional
        A pretrained emission network, kept frozen in the online SLAM; None learns it online.
    progress : bool, optional
        Show the runner's progress bar, default False.
    desc : str, optional
        Its description (default ``cfg.method``).

    Returns
    -------
    ExploreResult
        Poses, controls, scans, estimates, curves and timings.

    Raises
    ------
    ValueError
        If ``steps < 2``.
    """
    import dataclasses

    from cogmap.envs.episode import run

    if steps < 2:
        raise ValueError(f"explore: steps must be >= 2, got {steps}")
    sim = MazeSim(maze, noise=ROBOT_NOISE, seed=cfg.seed + 1)
    tic = time.perf_counter()
    try:
        pose = sim.reset(start_pose(maze, cfg.seed))
        scan = sim.lidar()
        slam = None
        if cfg.method == "mi" or cfg.learn_map:
            from cogmap.inference.online_slam import OnlineSLAM, SLAMConfig

            model = maze_config(maze.size, maze.map_side, ROBOT_NOISE.rot_std)
            sc = SLAMConfig(model=model, seed=cfg.seed, train_every=cfg.train_every, train_iters=cfg.train_iters,
                            freeze_emission=emission is not None)
            slam = OnlineSLAM(pose, sc, steps + cfg.train_every, emission=emission, first_scan=scan)
        if cfg.method == "mi":
            mi = cfg.mi if cfg.mi.max_step == cfg.max_step and cfg.mi.max_turn == cfg.max_turn else \
                dataclasses.replace(cfg.mi, max_step=cfg.max_step, max_turn=cfg.max_turn)
            policy = MIAgent(MIPlanner(model, mi, maze.size, cfg.seed, cfg.penalty_from), slam, cfg,
                             np.random.default_rng([cfg.seed, 5]))
        else:
            policy = (RandomWalk(cfg, cfg.seed) if cfg.method == "random"
                      else Frontier(maze, cfg, cfg.seed, sim.lidar_range))
        episode = MazeEpisode(sim, maze, cfg.curve_every, slam, steps, (pose, scan))
        run(episode, MazePilot(policy), steps - 1, outcome=(pose, scan, 0), progress=progress, desc=desc or cfg.method)
        tr, curves = episode.record.traversal(), episode.curves
        est = slam.estimates[:steps].copy() if slam is not None else None
        return ExploreResult(tr.poses, tr.controls, tr.scans, est, curves.ratio, curves.info,
                             getattr(policy, "plan_seconds", []), int(tr.blocked.sum()),
                             getattr(policy, "pulled", 0), params=slam.params if slam else None,
                             model=slam.config.model if slam else None, seconds=time.perf_counter() - tic)
    finally:
        sim.close()

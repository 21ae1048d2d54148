"""The AIMAPP agent: one thin stateful shell over the pure pieces (sections 3.1-3.6).

Each :meth:`AIMAPPAgent.step` runs sense -> infer -> learn -> plan and returns where to go:

1. *sense* (``_observe``): the panorama becomes an observation id through the encoder (a new id
   grows A_o); the believed pose is the odometry pose mapped by ``frame``, the rigid transform
   (yaw + translation) of the last re-localisation; panorama, LiDAR returns and obstacle flags
   are turned into that belief frame (``_to_belief``), and waypoints back to odometry.
2. *infer* (``_infer``): the inference scheme named by ``AgentConfig.scheme`` (the paper's
   single-factor Bayes filter by default; any registered scheme that accepts the model) combines
   the B_s prediction of the last move with A_o and A_p evidence; the confidence test scores the
   result (``confidence.py``).
3. *learn* (``_update``): when confident, A_o ties the observation to the believed state, a
   recognised place corrects the pose drift (``correction.py``: panorama shift for the heading,
   LiDAR alignment with the place's anchor for the position), the executed or failed move updates B_s
   with the Table 7 rates, the obstacle signal adds predicted (im)possible transitions, and free
   directions where no state lies yet expand the map when Eq. (7) says so. When unsure between
   nearby states only A_o learns, under the posterior. When the lost test fires, nothing is
   learnt until a familiar view singles out a place again.
4. *plan* (``_decide``): MCTS over expected free energy (exploration, or goal mode with the
   inductive term); when lost, a step in a free direction, seeking familiar views.

Degraded sensing (``None`` inputs; the paper's resilience to sensor failure, section 4.3): each
stream is used while it reports. Without the LiDAR, the camera still localises and A_o and B_s
still learn, but the map does not expand (nothing says which directions are free) and only
moves along known transitions are planned. Without the camera, odometry (A_p) localises and the
LiDAR still expands the map. Without odometry nothing places the agent on the map: it stays and
resumes with the same model and beliefs when the stream returns.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from cogmap import inference
from cogmap.genmodel import Factor, InductiveSpec, Modality, Model, ModelSpec, PoseSpec, SparseA, SparseB, compile
from cogmap.genmodel.numerics import wrap_angle
from cogmap.inference.learning import Event, learn_observation, learn_transition
from cogmap.inference.se2 import SE2, apply, apply_pose, compose, invert, rotate

from . import planner
from .confidence import Confidence, assess, cusum
from .config import AgentConfig
from .correction import Anchor, relocalise, to_frame_panorama, track
from .encoder import Encoder, check_encoder, make_encoder
from .mapping import centre_in_passage, direction, expansion_free_energies, reverse_heading
from .sensing import blocked
from .viewmap import ViewMap


@dataclass
class Sensed:
    """What the robot reports at one step; ``None`` marks a stream that did not report.

    The agent turns panorama, obstacle flags and scan into its belief frame before using them.

    Attributes
    ----------
    panorama : numpy.ndarray or None
        360-degree camera image, ``(H, W, 3)`` uint8 RGB (any image the encoder takes); None
        while the camera is silent.
    obstacles : numpy.ndarray or None
        ``(num_headings,)`` bool, one per heading (odometry frame): an obstacle lies within the
        move's corridor; None while the LiDAR is silent.
    odometry : numpy.ndarray or None
        ``(3,)`` float odometry pose ``(x, y, yaw)``, metres and radians; None while odometry is
        silent.
    moved : bool or None
        Outcome of the last motion command (False: the controller reported it blocked); None when
        no command was given.
    scan : numpy.ndarray or None
        ``(n, 2)`` float LiDAR returns relative to the robot, metres, axes of the odometry frame;
        optional (None: no scan, only the obstacle flags).
    sweep : numpy.ndarray or None
        ``(beams, 2)`` float end point of every beam in beam order (a beam that returned nothing
        ends at the LiDAR's range), relative to the robot, axes of the odometry frame: the area
        the scan swept, for the agent's sensed grid; optional (None: the grid is drawn from the
        returns' rays).
    """

    panorama: np.ndarray | None
    obstacles: np.ndarray | None  # one bool per heading: obstacle within reach
    odometry: np.ndarray | None  # (x, y, yaw) in the odometry frame
    moved: bool | None = None  # outcome of the last motion command (None: no command)
    scan: np.ndarray | None = None  # optional LiDAR returns relative to the robot (odometry frame, (n, 2))
    sweep: np.ndarray | None = None  # optional end points of every beam (max range where nothing returned)
    # the agent turns panorama, obstacles and scan into its belief frame before using them

    @property
    def missing(self) -> tuple[str, ...]:
        """The streams that did not report: a subset of ("camera", "lidar", "odometry")."""
        streams = (("camera", self.panorama), ("lidar", self.obstacles), ("odometry", self.odometry))
        return tuple(name for name, value in streams if value is None)


@dataclass
class Decision:
    """What one :meth:`AIMAPPAgent.step` decided.

    Attributes
    ----------
    action : int
        Control index: a heading ``0 .. num_headings - 1`` or ``num_headings`` (stay).
    waypoint : numpy.ndarray
        ``(2,)`` float where to drive, metres, odometry frame.
    state : int
        Most probable current state (-1 while paused before any decision).
    target : int
        State the move is expected to reach (== ``state`` for stay or a direction with no state).
    mode : str
        ``"explore"``, ``"goal"``, ``"relocalise"`` (lost) or ``"paused"`` (odometry silent).
    confidence : cogmap.agent.confidence.Confidence or None
        The confidence test of this step (A.1.2); None when paused.
    expanded : int
        Number of states the map gained this step (Eq. 7 expansion).
    efe : dict
        The planner's summary when MCTS ran (root ``actions``, values ``Q`` and ``visits``, the
        ``objective``, the planning ``arrays``, the ``obstacles`` flags and, while a view-weighted
        target is pursued, the ``preferred`` states); empty otherwise.
    missing : tuple of str
        Streams that did not report at this step (see :attr:`Sensed.missing`).
    """

    action: int
    waypoint: np.ndarray  # odometry frame
    state: int
    target: int  # state the move is expected to reach (== state for stay / unknown)
    mode: str  # "explore", "goal", "relocalise" (lost) or "paused" (a sensor is silent)
    confidence: Confidence | None = None
    expanded: int = 0
    efe: dict = field(default_factory=dict)
    missing: tuple[str, ...] = ()  # streams that did not report at this step


def initial_model(cfg: AgentConfig, pose0) -> Model:
    """One state at the start pose, one observation slot, nothing learnt (section 3.1).

    A single growable ``place`` factor with ``cfg.num_actions`` controls (stay last, B_s says
    every control stays), a growable ``view`` modality A_o with ``prior_count`` mass, the pose
    likelihood A_p (state poses, headings, step ``influence_radius``, width ``cfg.sigma``) and
    the inductive term's settings (Eq. 9).

    Parameters
    ----------
    cfg : AgentConfig
        The agent's parameters.
    pose0 : array_like
        Start position ``(x, y)`` (a longer pose: only x, y are read), metres, belief frame.

    Returns
    -------
    cogmap.genmodel.Model
        The compiled model, capacity ``cfg.initial_capacity`` states and observations.
    """
    u = cfg.num_actions
    headings = 2 * np.pi * np.arange(cfg.num_headings) / cfg.num_headings
    succ = np.zeros((1, u, 2), dtype=int)
    prob = np.zeros((1, u, 2))
    prob[:, :, 0] = 1.0
    spec = ModelSpec(
        factors=[Factor("place", 1, num_controls=u, growable=True, capacity=cfg.initial_capacity, stay=cfg.stay)],
        modalities=[Modality("view", 1, ("place",), growable=True, capacity=cfg.initial_capacity)],
        A={"view": SparseA(np.full(1, cfg.prior_count))},
        B={"place": SparseB(succ, prob, counts=np.where(prob > 0, cfg.prior_count, 0.0))},
        pose=PoseSpec("place", np.asarray(pose0, dtype=float)[None, :2], headings, cfg.influence_radius,
                      cfg.influence_radius, cfg.sigma),
        inductive=InductiveSpec(cfg.inductive_threshold, cfg.inductive_depth, cfg.inductive_weight),
    )
    return compile(spec, prior_count=cfg.prior_count)


class AIMAPPAgent:
    """Owns the model, beliefs, pose correction, encoder and RNG; contains no maths.

    The model is created at the first :meth:`step` (one state at the first believed pose) unless
    one is given (a learnt model, e.g. for goal reaching).

    Parameters
    ----------
    config : AgentConfig or None, optional
        The agent's parameters; None (default) for the paper's defaults.
    encoder : Encoder or None, optional
        Observation encoder; None (default) builds the one named by ``config.encoder``.
    seed : int, optional
        Seed of the agent's RNG (MCTS, moves while lost), default 0.
    model : cogmap.genmodel.Model or None, optional
        A model to start from; None (default): built at the first step.

    Attributes
    ----------
    cfg : AgentConfig
        The parameters.
    encoder : Encoder
        Image -> observation id.
    model : cogmap.genmodel.Model or None
        The generative model (None before the first step).
    q : numpy.ndarray or None
        ``(num_states,)`` posterior over states after the last step.
    frame : cogmap.inference.se2.SE2
        Odometry frame -> belief frame (drift correction, section 3.3).
    anchors : dict of int to Anchor
        State -> view and scan of its first confident visit (drift correction).
    last : Decision or None
        The last decision.
    goal_obs : int or None
        The preferred observation in goal mode (None: exploring).
    lost : bool
        The lost test fired and the agent is re-localising.
    corrections, lost_events, relocalisations, step_count : int
        Counters: accepted drift corrections, times lost, times found again, steps taken.
    views : ViewMap
        What the LiDAR has sensed (exploration planning).

    Raises
    ------
    KeyError
        When ``config.encoder`` names no registered encoder.
    TypeError
        When the encoder does not follow the :class:`Encoder` protocol.
    """

    def __init__(self, config: AgentConfig | None = None, encoder: Encoder | None = None, seed: int = 0,
                 model: Model | None = None):
        self.cfg = config or AgentConfig()
        self.encoder: Encoder = encoder if encoder is not None else make_encoder(self.cfg.encoder, self.cfg)
        check_encoder(self.encoder)
        inference.get(self.cfg.scheme)  # an unknown scheme: a KeyError naming the registered ones
        if model is not None:
            self._check_scheme(model)
        self.rng = np.random.default_rng(seed)
        self.model = model
        self.q: np.ndarray | None = None
        self.frame = SE2()  # odometry frame -> belief frame (drift correction, section 3.3)
        self.anchors: dict[int, Anchor] = {}  # state -> view and scan of its first confident visit
        self.corrections = 0  # accepted drift corrections
        # every move of the belief frame: {"step", "kind", "moved_m"}, kind "correction" (_correct) or
        # "relocalisation" (_update: found again after being lost, or a recognised view without LiDAR);
        # moved_m = how far the believed position of the robot moved (m)
        self.frame_moves: list[dict] = []
        self.last: Decision | None = None
        self.goal_obs: int | None = None
        self.step_count = 0
        self._outcome: bool | None = None  # reported outcome of the last real motion command
        self.lost = False  # the confidence test fired: re-localising
        self.lost_evidence = 0.0  # CUSUM statistic of conflict
        self.lost_events = 0
        self.last_obs: int | None = None
        self.relocalisations = 0
        self.views = ViewMap(self.cfg)  # what the LiDAR has sensed (exploration planning only)
        self.scanned: set[int] = set()  # states the agent has stood on with its LiDAR reporting
        # (state, heading, state) moves the robot has driven (and their reverses): their way is known
        # passable, so only an obstacle within the robot's own width blocks them (_path_blocked)
        self.traversed: set[tuple[int, int, int]] = set()

    # -- public ------------------------------------------------------------------------------
    @property
    def num_states(self) -> int:
        """Number of live states of the map (0 before the first step)."""
        return 0 if self.model is None else self.model.num_states[0]

    @property
    def poses(self) -> np.ndarray:
        """``(num_states, 2)`` float stored state positions, metres, belief frame."""
        return self.model.pose.poses[: self.num_states]

    @property
    def offset(self) -> np.ndarray:
        """Translation part of the odometry -> belief transform."""
        return self.frame.t

    def believed_pose(self, odometry) -> np.ndarray:
        """Believed (x, y) of an odometry pose (``frame`` applied).

        Parameters
        ----------
        odometry : array_like
            Odometry pose ``(x, y[, yaw])``, metres; only x, y are read.

        Returns
        -------
        numpy.ndarray
            ``(2,)`` float position, metres, belief frame.
        """
        return apply(self.frame, np.asarray(odometry, dtype=float)[:2])

    def believed_pose_yaw(self, odometry) -> np.ndarray:
        """Believed (x, y, yaw) of an odometry pose (x, y, yaw).

        Parameters
        ----------
        odometry : array_like
            ``(3,)`` odometry pose, metres and radians (a ``(2,)`` position gives a position).

        Returns
        -------
        numpy.ndarray
            ``(3,)`` float pose in the belief frame, yaw wrapped to [-pi, pi).
        """
        return apply_pose(self.frame, odometry)

    def to_odometry(self, xy) -> np.ndarray:
        """A belief-frame point in the odometry frame (where the simulator drives).

        Parameters
        ----------
        xy : array_like
            ``(..., 2)`` points, metres, belief frame.

        Returns
        -------
        numpy.ndarray
            ``(..., 2)`` float points, metres, odometry frame.
        """
        return apply(invert(self.frame), xy)

    def _shift_frame(self, delta) -> None:
        """Translate the belief frame by ``delta`` (belief-frame metres)."""
        self.frame = compose(SE2(0.0, float(delta[0]), float(delta[1])), self.frame)

    @property
    def at_goal(self) -> bool:
        """The last step confidently observed the goal observation."""
        last = self.last
        return (self.goal_obs is not None and self.last_obs == self.goal_obs and last is not None
                and last.confidence is not None and last.confidence.confident)

    def localise_at(self, odometry) -> int:
        """Known start (section 4.1 goal protocol): believe the state nearest ``odometry``.

        The posterior becomes one-hot on that state, the belief frame is shifted so the believed
        pose is the state's stored pose, and the last decision is forgotten.

        Parameters
        ----------
        odometry : array_like
            Current odometry pose ``(x, y[, yaw])``, metres.

        Returns
        -------
        int
            The state now believed.
        """
        s, _ = self.model.pose_index().nearest(self.believed_pose(odometry))
        self.q = np.zeros(self.num_states)
        self.q[s] = 1.0
        self._shift_frame(self.poses[s] - self.believed_pose(odometry))
        self.last, self._outcome = None, None
        return s

    def set_goal(self, obs: int | None) -> None:
        """Prefer observation ``obs`` (goal mode, section 4.4), or return to exploration with ``None``.

        Parameters
        ----------
        obs : int or None
            Observation id of the goal: C puts log-preference 1 on it (0 elsewhere), weighted by
            ``cfg.goal_weight`` when planning. None clears the preference.

        Raises
        ------
        ValueError
            When ``obs`` is not a known observation id.
        """
        if obs is not None and not 0 <= obs < self.model.num_obs[0]:
            raise ValueError(f"goal observation {obs} is unknown (have {self.model.num_obs[0]})")
        self.goal_obs = obs
        self.model.C[0][:] = 0.0
        if obs is not None:
            self.model.C[0][obs] = 1.0

    def goal_states(self, min_prob: float = 0.5) -> np.ndarray:
        """States whose observation model favours the goal observation.

        Parameters
        ----------
        min_prob : float, optional
            A state counts when ``A_o[goal, s]`` is at least this fraction of the largest entry
            of that row (and at least 1e-9), default 0.5.

        Returns
        -------
        numpy.ndarray
            Int state indices, ascending; empty without a goal.
        """
        if self.goal_obs is None:
            return np.zeros(0, dtype=int)
        row = self.model.A_row(0, self.goal_obs)
        return np.flatnonzero(row >= max(min_prob * row.max(), 1e-9))

    def step(self, sensed: Sensed) -> Decision:
        """One sense -> infer -> learn -> plan cycle (sections 3.1-3.6, see the module docstring).

        Parameters
        ----------
        sensed : Sensed
            What the robot reports now (odometry frame); ``moved`` is the outcome of the command
            of the previous decision.

        Returns
        -------
        Decision
            Where to go next (waypoint in the odometry frame) and why; mode ``"paused"`` (stay,
            nothing changed) while odometry is silent, or before the model exists while any
            stream is.
        """
        self.step_count += 1
        if self.last is not None and self._outcome is None and sensed.moved is not None:
            self._outcome = bool(sensed.moved)  # outcome of the last real motion command
        missing = sensed.missing
        if "odometry" in missing or (self.model is None and missing):
            return self._paused(sensed)  # nothing places the agent (or a first view is incomplete)
        pose = self.believed_pose(sensed.odometry)
        if self.model is None:
            self.model = self._check_scheme(initial_model(self.cfg, pose))
            self.q = np.ones(1)
        local = self._to_belief(sensed)
        obs, score = self._observe(local.panorama) if local.panorama is not None else (None, 0.0)
        q, conf = self._infer(obs, pose)
        if self._correct(q, conf, local, pose):  # a recognised place moved the belief frame
            self._record_frame_move("correction", pose, sensed.odometry)
            pose = self.believed_pose(sensed.odometry)
            local = self._to_belief(sensed)
        frame = self.frame
        expanded = self._update(q, conf, obs, local, pose, score)
        if self.frame is not frame:
            self._record_frame_move("relocalisation", pose, sensed.odometry)
        self.views.blind = sensed.scan is None
        if not self.lost and sensed.scan is not None:  # what the LiDAR swept, through the corrected frame
            self.views.observe(self, sensed)
            if conf.confident:
                self.scanned.add(int(np.argmax(q)))
        decision = self._decide(local, pose, conf, expanded)
        decision.missing = missing
        self.last, self._outcome = decision, None
        return decision

    def _record_frame_move(self, kind: str, before, odometry) -> None:
        """Note in :attr:`frame_moves` how far the belief frame's change moved the believed position."""
        moved = float(np.hypot(*(self.believed_pose(odometry) - np.asarray(before)[:2])))
        self.frame_moves.append({"step": self.step_count, "kind": kind, "moved_m": moved})

    # -- the cycle -------------------------------------------------------------------------
    def _paused(self, sensed: Sensed) -> Decision:
        """Odometry is silent (or the very first view is incomplete): stay, change nothing,
        resume when it returns."""
        state = -1 if self.last is None else self.last.state
        here = np.zeros(2) if sensed.odometry is None else np.asarray(sensed.odometry, dtype=float)[:2]
        return Decision(self.cfg.stay, here, state, state, "paused", missing=sensed.missing)

    def _to_belief(self, sensed: Sensed) -> Sensed:
        """``sensed`` in the belief frame: panorama turned (images only), LiDAR returns rotated
        and the per-heading obstacle flags recomputed from them (or, without a scan, taken from
        the nearest odometry heading)."""
        yaw = self.frame.yaw
        if yaw == 0.0:
            return sensed
        cfg = self.cfg
        pano = sensed.panorama
        if pano is not None and np.ndim(pano) >= 2:
            pano = to_frame_panorama(pano, yaw)
        scan = None if sensed.scan is None else rotate(self.frame, sensed.scan)
        sweep = None if sensed.sweep is None else rotate(self.frame, sensed.sweep)
        if scan is not None:
            h = 2 * np.pi * np.arange(cfg.num_headings) / cfg.num_headings
            moves = cfg.influence_radius * np.stack([np.cos(h), np.sin(h)], axis=1)
            obstacles = blocked(scan, moves, cfg.robot_radius + cfg.obstacle_margin)
        elif sensed.obstacles is not None:
            k = int(np.round(yaw * cfg.num_headings / (2 * np.pi)))
            obstacles = np.roll(np.asarray(sensed.obstacles, dtype=bool), k)
        else:  # the LiDAR is silent
            obstacles = None
        return Sensed(pano, obstacles, sensed.odometry, sensed.moved, scan, sweep)

    def _correct(self, q: np.ndarray, conf: Confidence, local: Sensed, pose: np.ndarray) -> bool:
        """Drift correction (section 3.3): when the posterior confidently names a state that has
        an anchor and the view and scan recognise it (``correction.relocalise``), the belief
        frame is corrected by a rigid transform. Returns whether it was."""
        cfg = self.cfg
        if self.lost or not conf.confident or local.scan is None:
            return False
        state = int(np.argmax(q))
        last = self.last
        if last is not None and last.state == state:
            return False  # compare once per arrival
        reach = cfg.relocalise_max_correction * cfg.influence_radius
        anchor = self.anchors.get(state)
        if anchor is not None and np.ndim(local.panorama) >= 2:  # a revisit: the place's own view and scan
            if np.hypot(*(pose - anchor.pose)) > cfg.influence_radius + reach:
                return False
            r = relocalise(anchor, np.asarray(local.panorama), local.scan, pose,
                           max_shift=cfg.relocalise_max_shift, min_ssim=cfg.relocalise_align_ssim,
                           min_inliers=cfg.relocalise_inliers, max_translation=reach)
        elif anchor is None and cfg.track_anchors and last is not None and last.state in self.anchors:
            # a first visit: the scan of the place just left is still in view
            r = track(self.anchors[last.state], local.scan, pose, min_inliers=cfg.track_inliers,
                      max_translation=cfg.track_max_correction * cfg.influence_radius)
        else:
            return False
        if not r.accepted:
            return False
        moved = float(np.hypot(*(apply(r.correction, pose) - pose)))
        if moved < cfg.min_correction and abs(r.correction.yaw) < cfg.min_correction_yaw:
            return False  # within the alignment's own error: keep the frame
        self.frame = compose(r.correction, self.frame)
        self.corrections += 1
        return True

    def _check_scheme(self, model: Model) -> Model:
        if not inference.accepts(self.cfg.scheme, model):
            raise ValueError(f"AgentConfig.scheme: inference scheme '{self.cfg.scheme}' does not accept AIMAPP's "
                             f"model; schemes that do: {', '.join(inference.accepting(model))}")
        return model

    def _observe(self, panorama) -> tuple[int, float]:
        """Observation id (a new id grows A_o) and the encoder's best similarity score."""
        obs, _ = self.encoder(panorama)
        self.last_obs = obs
        while self.model.num_obs[0] <= obs:
            # a column's prior mass stays prior_count however many outcomes exist (SparseA), so a
            # taught column keeps its certainty as the vocabulary of views grows
            self.model.add_observation(0)
        return obs, float(np.max(self.encoder.last_scores, initial=0.0))

    def _infer(self, obs: int | None, pose: np.ndarray) -> tuple[np.ndarray, Confidence]:
        """Posterior over states and the confidence test (section 3.3, A.1.2); ``obs`` is None
        while the camera is silent (the pose evidence alone then localises)."""
        cfg = self.cfg
        scheme = inference.get(cfg.scheme)  # the paper's exact filter by default (AgentConfig.scheme)
        if self.lost:  # re-localising: odometry is not trusted, only what is seen
            prior = self._visited_prior()
            q = [prior] if obs is None else scheme(self.model, [prior], [{"view": obs}])[0]
        else:  # B_s prediction combined with A_o and A_p evidence
            prior = self._prior(self._outcome)
            q, _ = scheme(self.model, [prior], [{"view": obs, "pose": pose}])
        q = q[0]
        d2 = np.sum((self.poses - pose) ** 2, axis=1)
        near = np.exp(-(d2 - d2.min()) / (2 * cfg.influence_radius**2))  # where the pose says we are
        row = None if obs is None else self.model.A_row(0, obs)
        conf = assess(q, near, row, cfg.z_threshold, self.lost_evidence, cfg.lost_slack)
        return q, conf

    def _update(self, q: np.ndarray, conf: Confidence, obs: int | None, sensed: Sensed, pose: np.ndarray,
                score: float) -> int:
        """Lost/found bookkeeping and learning; returns how many states the map gained."""
        cfg = self.cfg
        state = int(np.argmax(q))
        expanded = 0
        if not self.lost and conf.conflict > cfg.lost_slack and self._scan_agrees(sensed, pose):
            # the view points elsewhere but the LiDAR matches the place the belief is at: aliasing
            # (repeated racks, similar rooms), not a wrong position; it adds no evidence of being lost
            evidence = cusum(self.lost_evidence, 0.0, cfg.lost_slack)
            conf = conf._replace(conflict=0.0, lost_evidence=evidence, confident=conf.dominance >= cfg.z_threshold)
        if self.lost:
            # a familiar view singles out a place (and, with a LiDAR, the scan confirms it)
            if obs is not None and q[state] >= 0.5 and self._recognised(state, obs) and self._found_at(
                    state, sensed, pose):
                self.lost, self.lost_evidence = False, 0.0
                self.relocalisations += 1
        elif conf.lost(cfg.z_threshold):
            self.lost, self.lost_evidence = True, 0.0
            self.lost_events += 1
            q = self._visited_prior()
        else:
            self.lost_evidence = conf.lost_evidence
            if conf.confident:
                expanded = self._learn(state, obs, sensed, pose, score)
            elif obs is not None:  # unsure between nearby states: learn A_o under the posterior (Eq. 8)
                learn_observation(self.model, 0, obs, [q], lr=cfg.obs_learning_rate)
        self.q = np.zeros(self.num_states)
        self.q[: q.size] = q
        return expanded

    def _decide(self, sensed: Sensed, pose: np.ndarray, conf: Confidence, expanded: int) -> Decision:
        cfg = self.cfg
        state = int(np.argmax(self.q))
        if self.lost:
            # The map position is unknown, so the graph cannot guide a move: step in a free
            # direction of the real surroundings until a familiar view is recognised.
            if sensed.obstacles is None:  # nothing says which way is free: wait for the LiDAR
                return Decision(cfg.stay, self.to_odometry(pose), state, state, "relocalise", conf, expanded)
            free = np.flatnonzero(~np.asarray(sensed.obstacles, dtype=bool))
            action = int(self.rng.choice(free)) if free.size else cfg.stay
            waypoint = pose if action == cfg.stay else pose + cfg.influence_radius * direction(action, cfg.num_headings)
            return Decision(action, self.to_odometry(waypoint), state, state, "relocalise", conf, expanded)
        mode = "goal" if self.goal_obs is not None else "explore"
        flags = self._move_obstacles(state, sensed.obstacles, sensed.scan, pose)
        action, efe = planner.decide(self, state, flags, mode)
        target, waypoint = self._waypoint(state, action)
        return Decision(action, self.to_odometry(waypoint), state, target, mode, conf, expanded, efe)

    # -- pieces ------------------------------------------------------------------------------
    def _prior(self, moved: bool | None) -> np.ndarray:
        """Predicted belief after the last move (Eq. 1: B_s applied to the last posterior).

        A move the controller reported blocked is learnt first (experienced impossible, Table 7)
        and predicts no change of state."""
        n = self.num_states
        q = np.zeros(n)
        q[: self.q.size] = self.q
        last = self.last
        if last is None or last.action == self.cfg.stay:
            return q
        if moved is False:  # blocked: the robot stopped near where it started
            if last.target != last.state:
                learn_transition(self.model, 0, last.state, last.action, last.target, Event.IMPOSSIBLE,
                                 reverse_control=self._reverse(last.action), rates=self.cfg.learning)
            return q
        return self.model.predict(0, q, last.action)

    def _reverse(self, action: int) -> int | None:
        return reverse_heading(action, self.cfg.num_headings) if action != self.cfg.stay else None

    def scanned_from(self) -> np.ndarray:
        """Mask of states the agent has stood on with its LiDAR reporting: what their view can
        reveal has been seen (a state passed while the LiDAR was silent still promises it).

        Returns
        -------
        numpy.ndarray
            ``(num_states,)`` bool.
        """
        mask = np.zeros(self.num_states, dtype=bool)
        mask[list(self.scanned)] = True
        return mask

    def visited(self) -> np.ndarray:
        """Mask of states whose observation model has been taught (the agent has been there).

        Returns
        -------
        numpy.ndarray
            ``(num_states,)`` bool: the largest count of the state's A_o column exceeds
            ``2 * prior_count``.
        """
        return self.model.A[0].taught(2 * self.cfg.prior_count)

    def _scan_agrees(self, sensed: Sensed, pose: np.ndarray) -> bool:
        """The LiDAR scan aligns, within the tracking gate, with the anchor of the nearest
        anchored state around the believed pose (False without a scan or an anchor nearby)."""
        cfg = self.cfg
        if sensed.scan is None or not self.anchors:
            return False
        states = np.fromiter(self.anchors, dtype=int)
        d = np.hypot(*(self.poses[states] - pose).T)
        k = int(np.argmin(d))
        if d[k] > 1.5 * cfg.influence_radius:
            return False
        r = track(self.anchors[int(states[k])], sensed.scan, pose, min_inliers=cfg.relocalise_inliers,
                  max_translation=cfg.track_max_correction * cfg.influence_radius)
        return r.accepted

    def _found_at(self, state: int, sensed: Sensed, pose: np.ndarray) -> bool:
        """Re-localise on ``state`` after being lost; returns whether the belief frame moved.
        With the state's anchor and a scan, the view (heading) and the scan (position) must
        align with it, as in :func:`correction.relocalise` from the anchor's pose; otherwise the
        belief moves onto the state's stored pose."""
        cfg = self.cfg
        anchor = self.anchors.get(state)
        if anchor is None or sensed.scan is None or np.ndim(sensed.panorama) < 2:
            self._shift_frame(self.poses[state] - pose)  # trust the map's pose
            return True
        r = relocalise(anchor, np.asarray(sensed.panorama), sensed.scan, anchor.pose,
                       max_shift=cfg.relocalise_max_shift, min_ssim=cfg.relocalise_align_ssim,
                       min_inliers=cfg.relocalise_inliers, max_translation=cfg.influence_radius)
        if not r.accepted:
            return False
        # move the believed pose onto the anchor's, then apply the alignment found from there
        self.frame = compose(compose(r.correction, SE2(0.0, *(anchor.pose - pose))), self.frame)
        return True

    def _recognised(self, state: int, obs: int) -> bool:
        """``obs`` has been tied to ``state`` before and to no other state as strongly."""
        m = self.model
        counts = m.pA_row(0, obs)
        return counts[state] > 2 * self.cfg.prior_count and counts.argmax() == state

    def _visited_prior(self) -> np.ndarray:
        visited = self.visited()
        return visited / visited.sum() if visited.any() else np.full(self.num_states, 1.0 / self.num_states)

    def _learn(self, state: int, obs: int | None, sensed: Sensed, pose: np.ndarray, score: float) -> int:
        m, cfg = self.model, self.cfg
        if obs is not None:
            onehot = np.zeros(self.num_states)
            onehot[state] = 1.0
            if sensed.scan is None and self._recognised(state, obs) and score >= cfg.relocalise_ssim:
                # no LiDAR to align: a familiar, nearly identical view re-localises onto the state's pose
                self._shift_frame(self.poses[state] - pose)
            elif state not in self.anchors and sensed.scan is not None and np.ndim(sensed.panorama) >= 2:
                self.anchors[state] = Anchor(pose.copy(), np.asarray(sensed.panorama).copy(), sensed.scan.copy(),
                                             self.step_count)
            learn_observation(m, 0, obs, [onehot], lr=cfg.obs_learning_rate)
        last = self.last
        arrived = last is None or state != last.state
        if last is not None and self._outcome and state != last.state and last.action != cfg.stay:
            learn_transition(m, 0, last.state, last.action, state, Event.POSSIBLE,
                             reverse_control=self._reverse(last.action), rates=cfg.learning)
            self.traversed.add((int(last.state), int(last.action), state))
            self.traversed.add((state, int(self._reverse(last.action)), int(last.state)))
        if not arrived or sensed.obstacles is None:  # without the LiDAR, no free direction is known
            return 0
        return self._expand(state, np.asarray(sensed.obstacles, dtype=bool), sensed.scan, pose)

    def _neighbours_by_heading(self, state: int) -> np.ndarray:
        """For each heading, the nearest state lying in that direction (bearing within half a
        heading sector, at most 1.5 influence radii away), or -1."""
        cfg = self.cfg
        idx, dist = self.model.pose_index().near(self.poses[state], 1.5 * cfg.influence_radius)
        keep = dist > 1e-9
        idx, dist = idx[keep], dist[keep]
        rel = self.poses[idx] - self.poses[state]
        bearing = np.arctan2(rel[:, 1], rel[:, 0])
        sector = np.pi / cfg.num_headings
        out = np.full(cfg.num_headings, -1)
        for h in range(cfg.num_headings):
            off = np.abs(wrap_angle(bearing - 2 * np.pi * h / cfg.num_headings))
            ok = off <= sector + 1e-9
            if ok.any():
                out[h] = int(idx[ok][np.argmin(dist[ok])])  # ties: the lowest index, as before
        return out

    def _path_blocked(self, heading: int, target: int, obstacles: np.ndarray, scan: np.ndarray | None,
                      pose: np.ndarray, state: int | None = None) -> bool:
        """Would the move toward ``target`` collide? With a scan, its corridor is checked along
        the actual bearing and length from ``pose`` to the target (what the robot will drive);
        otherwise the heading's flag is used. The corridor is the robot's width plus
        ``obstacle_margin``, except for a move from ``state`` the robot has driven before (either
        way, :attr:`traversed`): a return within the margin alone does not block a way known
        passable (else a doorway passed near its jamb would cut the map in two), while anything
        within the robot's own width (e.g. a box moved onto the way) still does."""
        if scan is None:
            return bool(obstacles[heading])
        cfg = self.cfg
        move = self.poses[target] - pose
        if not blocked(scan, move, cfg.robot_radius + cfg.obstacle_margin)[0]:
            return False
        if state is not None and (int(state), int(heading), int(target)) in self.traversed:
            return bool(blocked(scan, move, cfg.robot_radius)[0])
        return True

    def _move_obstacles(self, state: int, obstacles: np.ndarray | None, scan: np.ndarray | None,
                        pose: np.ndarray) -> np.ndarray:
        """Collision flag per heading for the move the agent would make: toward the believed
        successor when there is one, else straight along the heading. Without the LiDAR only
        moves along known transitions are offered."""
        if obstacles is None:
            return np.array([self._waypoint(state, h)[0] == state for h in range(self.cfg.num_headings)])
        flags = np.asarray(obstacles, dtype=bool).copy()
        if scan is None:
            return flags
        for h in range(self.cfg.num_headings):
            target, _ = self._waypoint(state, h)
            if target != state:
                flags[h] = self._path_blocked(h, target, obstacles, scan, pose, state)
        return flags

    def _expand(self, state: int, obstacles: np.ndarray, scan: np.ndarray | None, pose: np.ndarray) -> int:
        """Predicted transitions from the obstacle signal, and Eq. (7) map expansion in free
        directions where no state lies yet."""
        m, cfg = self.model, self.cfg
        radius = cfg.node_spacing * cfg.influence_radius
        origin = self.poses[state].copy()
        neighbours = self._neighbours_by_heading(state)
        created = 0
        B = m.B[0]
        for h in range(cfg.num_headings):
            rev = reverse_heading(h, cfg.num_headings)
            n = int(neighbours[h])
            believed = {int(t) for t, p in zip(B.succ[state, h], B.prob[state, h], strict=True) if p > 0}
            for t in sorted((believed | {n}) - {state, -1}):  # states this move is believed to reach
                free = not self._path_blocked(h, t, obstacles, scan, pose, state)
                event = Event.PREDICTED_POSSIBLE if free and t == n else Event.PREDICTED_IMPOSSIBLE
                if free and t != n:
                    continue  # another state now lies in that direction: leave this link alone
                learn_transition(m, 0, state, h, t, event, reverse_control=rev, rates=cfg.learning)
            if obstacles[h] or n >= 0:
                continue
            if created >= cfg.lookahead_nodes:
                continue
            p_star = self._predicted_pose(origin, h, scan, pose)
            d_near = self.model.pose_index().nearest(p_star)[1]
            if expansion_free_energies(np.array([d_near]), radius, cfg.sigma)[0] < 0:  # Eq. (7)
                new = m.add_state(0, pose=p_star, obs_count=cfg.prior_count / m.num_obs[0])
                created += 1
                learn_transition(m, 0, state, h, new, Event.PREDICTED_POSSIBLE, reverse_control=rev,
                                 rates=cfg.learning)
        return created

    def _predicted_pose(self, origin: np.ndarray, heading: int, scan: np.ndarray | None,
                        pose: np.ndarray) -> np.ndarray:
        """Where a move along ``heading`` from the state at ``origin`` is predicted to lead: one
        influence radius along it, moved to the centre line of a corridor narrower than
        ``passage_width`` when the LiDAR shows one (and the move there is as free)."""
        cfg = self.cfg
        u = direction(heading, cfg.num_headings)
        p_star = origin + cfg.influence_radius * u
        if scan is None or cfg.passage_width <= 0:
            return p_star
        centred = centre_in_passage(p_star, u, pose + scan, cfg.passage_width, max_shift=0.5 * cfg.influence_radius)
        if blocked(scan, centred - pose, cfg.robot_radius + cfg.obstacle_margin)[0]:
            return p_star
        return centred

    def _waypoint(self, state: int, action: int) -> tuple[int, np.ndarray]:
        """Where an action leads: its most probable successor other than staying (as the planner
        saw it), or, for a direction with no state yet, one step along its heading."""
        cfg = self.cfg
        if action == cfg.stay:
            return state, self.poses[state].copy()
        B = self.model.B[0]
        prob = np.where(B.succ[state, action] != state, B.prob[state, action], 0.0)
        k = int(np.argmax(prob))
        if prob[k] > 0:
            target = int(B.succ[state, action, k])
            return target, self.poses[target].copy()
        return state, self.poses[state] + cfg.influence_radius * direction(action, cfg.num_headings)

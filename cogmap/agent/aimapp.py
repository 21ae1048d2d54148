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
from cogmap.inference.se2 import SE2, apply, apply_pose, invert

from . import planner
from .confidence import Confidence
from .config import AgentConfig
from .cycle import infer, update
from .encoder import Encoder, check_encoder, make_encoder
from .localisation import Belief, Counts, corrected_frame, empty_memory, shifted, to_belief
from .map_growth import (
    move_obstacles,
    state_poses,
    wander,
    waypoint,
)
from .sensing import Sensed

__all__ = ["AIMAPPAgent", "Decision", "Sensed", "initial_model"]


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


def checked_scheme(cfg: AgentConfig, model: Model) -> Model:
    """``model``, after checking that the inference scheme ``cfg.scheme`` accepts it.

    Parameters
    ----------
    cfg : AgentConfig
        Names the scheme.
    model : Model
        AIMAPP's model.

    Returns
    -------
    Model
        ``model`` itself.

    Raises
    ------
    ValueError
        The scheme does not accept the model (the message names those that do).
    """
    if not inference.accepts(cfg.scheme, model):
        raise ValueError(f"AgentConfig.scheme: inference scheme '{cfg.scheme}' does not accept AIMAPP's "
                         f"model; schemes that do: {', '.join(inference.accepting(model))}")
    return model


class AIMAPPAgent:
    """The AIMAPP agent: config, encoder, RNG, model and a state of three records; the maths lives in
    the functions it calls (:mod:`~cogmap.agent.cycle`, :mod:`~cogmap.agent.localisation`,
    :mod:`~cogmap.agent.map_growth`, :mod:`~cogmap.agent.planner`). The model is created at the
    first :meth:`step` unless one is given (a learnt model, e.g. for goal reaching).

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
    cfg, encoder, model
        The parameters, the image -> observation id encoder, the generative model (None before the
        first step).
    belief, counts, memory : Belief, Counts, Memory
        Posterior, belief frame and lost test (``q`` and ``frame`` are also properties); steps and
        events; anchors, states scanned from, moves driven, frame moves and the sensed grid.
    last : Decision or None
        The last decision.
    goal_obs : int or None
        The preferred observation in goal mode (None: exploring).

    Raises
    ------
    KeyError
        When ``config.encoder`` names no registered encoder, or ``config.scheme`` no scheme.
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
            checked_scheme(self.cfg, model)
        self.rng = np.random.default_rng(seed)
        self.model = model
        self.belief = Belief(None, SE2())
        self.counts = Counts()
        self.memory = empty_memory(self.cfg)
        self.last: Decision | None = None
        self.goal_obs: int | None = None

    # -- public ------------------------------------------------------------------------------
    @property
    def num_states(self) -> int:
        """Number of live states of the map (0 before the first step)."""
        return 0 if self.model is None else self.model.num_states[0]

    @property
    def poses(self) -> np.ndarray:
        """``(num_states, 2)`` float stored state positions, metres, belief frame."""
        return state_poses(self.model)

    @property
    def q(self) -> np.ndarray | None:
        """``(num_states,)`` posterior over states after the last step."""
        return self.belief.q

    @property
    def frame(self) -> SE2:
        """Odometry frame -> belief frame."""
        return self.belief.frame

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

    @property
    def at_goal(self) -> bool:
        """The last step confidently observed the goal observation."""
        last = self.last
        return (self.goal_obs is not None and self.belief.last_obs == self.goal_obs and last is not None
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
        q = np.zeros(self.num_states)
        q[s] = 1.0
        frame = shifted(self.frame, self.poses[s] - self.believed_pose(odometry))
        self.belief = self.belief._replace(q=q, frame=frame, outcome=None)
        self.last = None
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

    def scanned_from(self) -> np.ndarray:
        """Mask of states the agent has stood on with its LiDAR reporting: what their view can
        reveal has been seen (a state passed while the LiDAR was silent still promises it).

        Returns
        -------
        numpy.ndarray
            ``(num_states,)`` bool.
        """
        mask = np.zeros(self.num_states, dtype=bool)
        mask[list(self.memory.scanned)] = True
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
        self.counts = self.counts._replace(steps=self.counts.steps + 1)
        if self.last is not None and self.belief.outcome is None and sensed.moved is not None:
            self.belief = self.belief._replace(outcome=bool(sensed.moved))  # of the last real motion command
        missing = sensed.missing
        if "odometry" in missing or (self.model is None and missing):
            return self._paused(sensed)  # nothing places the agent (or a first view is incomplete)
        pose = self.believed_pose(sensed.odometry)
        if self.model is None:
            self.model = checked_scheme(self.cfg, initial_model(self.cfg, pose))
            self.belief = self.belief._replace(q=np.ones(1))
        local = to_belief(self.frame, self.cfg, sensed)
        obs, score = self._observe(local.panorama) if local.panorama is not None else (None, 0.0)
        q, conf = infer(self.model, self.cfg, self.belief, self.last, obs, pose)
        frame = corrected_frame(self.belief, self.memory.anchors, self.cfg, q, conf.confident, self.last, local, pose)
        if frame is not None:  # a recognised place moved the belief frame
            self.belief = self.belief._replace(frame=frame)
            self.counts = self.counts._replace(corrections=self.counts.corrections + 1)
            self._record_frame_move("correction", pose, sensed.odometry)
            pose = self.believed_pose(sensed.odometry)
            local = to_belief(self.frame, self.cfg, sensed)
        frame = self.frame
        self.belief, self.counts, expanded = update(self.model, self.cfg, self.belief, self.counts, self.memory,
                                                    self.last, q, conf, obs, local, pose, score)
        if self.frame is not frame:
            self._record_frame_move("relocalisation", pose, sensed.odometry)
        views = self.memory.views
        views.pursuit.blind = sensed.scan is None
        if not self.belief.lost and sensed.scan is not None:  # what the LiDAR swept, through the corrected frame
            views.observe(self.frame, sensed)
            if conf.confident:
                self.memory.scanned.add(int(np.argmax(self.q)))
        decision = self._decide(local, pose, conf, expanded)
        decision.missing = missing
        self.last = decision
        self.belief = self.belief._replace(outcome=None)
        return decision

    def _record_frame_move(self, kind: str, before, odometry) -> None:
        moved = float(np.hypot(*(self.believed_pose(odometry) - np.asarray(before)[:2])))
        self.memory.frame_moves.append({"step": self.counts.steps, "kind": kind, "moved_m": moved})

    def _paused(self, sensed: Sensed) -> Decision:
        """Odometry is silent (or the very first view is incomplete): stay, change nothing."""
        state = -1 if self.last is None else self.last.state
        here = np.zeros(2) if sensed.odometry is None else np.asarray(sensed.odometry, dtype=float)[:2]
        return Decision(self.cfg.stay, here, state, state, "paused", missing=sensed.missing)

    def _observe(self, panorama) -> tuple[int, float]:
        """Observation id (a new id grows A_o) and the encoder's best similarity score."""
        obs, _ = self.encoder(panorama)
        self.belief = self.belief._replace(last_obs=obs)
        while self.model.num_obs[0] <= obs:
            # a column's prior mass stays prior_count however many outcomes exist (SparseA), so a
            # taught column keeps its certainty as the vocabulary of views grows
            self.model.add_observation(0)
        return obs, float(np.max(self.encoder.last_scores, initial=0.0))

    def _decide(self, sensed: Sensed, pose: np.ndarray, conf: Confidence, expanded: int) -> Decision:
        cfg = self.cfg
        state = int(np.argmax(self.q))
        if self.belief.lost:  # the graph cannot guide a move: a free direction, seeking familiar views
            action, to = wander(cfg, self.rng, sensed.obstacles, pose)
            return Decision(action, self.to_odometry(to), state, state, "relocalise", conf, expanded)
        mode, goals = ("goal", self.goal_states()) if self.goal_obs is not None else ("explore", None)
        flags = move_obstacles(self.model, cfg, self.memory.traversed, state, sensed.obstacles, sensed.scan, pose)
        action, efe = planner.decide(self.model, cfg, self.q, self.rng, self.memory.views, self.scanned_from(), goals,
                                     state, flags, mode)
        target, to = waypoint(self.model, cfg, state, action)
        return Decision(action, self.to_odometry(to), state, target, mode, conf, expanded, efe)

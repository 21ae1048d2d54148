"""Every AIMAPP parameter in one place, with the paper's defaults (Table 6, A.1, Table 7)."""

from __future__ import annotations

import warnings
from dataclasses import asdict, dataclass, field, fields

from cogmap.inference.learning import LearningRates
from cogmap.planning.mcts import MCTSConfig
from cogmap.planning.sensed import check_bounds

#: AIMAPP's MCTS: depth 10, 30 simulations (Appendix A.3, Table 6), policy precision 8 (Eq. 4); a move
#: is planned only when it is believed to leave the state with probability above 0.1
AIMAPP_MCTS = MCTSConfig(depth=10, simulations=30, gamma=8.0, move_threshold=0.1)
#: the names of MCTSConfig's fields in an AgentConfig file (the others: ``mcts_<field>``)
_MCTS_KEYS = {"depth": "mcts_depth", "simulations": "mcts_simulations", "gamma": "gamma",
              "move_threshold": "min_move_probability", "count_information_once": "mcts_count_information_once",
              "discount": "mcts_discount"}
_MCTS_DEFAULT = MCTSConfig()


@dataclass(frozen=True)
class AgentConfig:
    """Every parameter of the AIMAPP agent, with the paper's defaults (frozen; change with ``replace``).

    Lengths are in metres, angles in radians, scores in nats unless said otherwise. Table 6
    (Appendix A.1) gives the headings, influence radius, lookahead nodes, SSIM threshold and MCTS
    depth and runs; Table 7 the transition learning rates; A.1.2 the confidence threshold. Fields
    that cite no table are choices of this implementation (the paper leaves them open).

    Attributes
    ----------
    num_headings : int
        Number of move directions, evenly spaced over 2 pi; with the stay control the agent has
        ``num_headings + 1`` controls (12 + 1 = 13 actions, Table 6).
    influence_radius : float
        Metres. Length of one move, spacing of new states and range of a state's pose kernel
        (Table 6: 1 m in small environments, 2 m in large ones). Also the unit of the correction
        limits below.
    robot_radius : float
        Metres. Physical radius of the robot (Table 6: robot-specific): with ``obstacle_margin``
        the half-width of the corridor a move must find free of LiDAR returns (obstacle signal,
        state creation), and the tolerance of the scan check on believed transitions.
    node_spacing : float
        Fraction of ``influence_radius``: the Eq. (7) expansion test scores a candidate state
        against the nearest stored pose with a new-state kernel at ``node_spacing *
        influence_radius``, so a predicted pose farther than about that from every node is added.
    lookahead_nodes : int
        At most this many new states are created per expansion, i.e. per arrival at a state
        (Table 6: 8).
    passage_width : float
        Metres. A predicted state in a corridor narrower than this (walls on both sides across
        the move over a metre along it, from the LiDAR) is placed on the corridor's centre line
        (:func:`cogmap.agent.mapping.centre_in_passage`), so a corridor holds one row of states;
        0 places every predicted state one influence radius along its heading, as the paper does.
    ssim_threshold : float
        In [0, 1]. Place recognition by the SSIM encoder: a panorama whose best SSIM against the
        stored views is at least this is the same observation (Table 6: 65 %); also the bar a
        goal image must pass (:func:`cogmap.goal.goal_observation`).
    encoder : str
        Name of the observation encoder (see :func:`cogmap.agent.encoder.register_encoder`);
        ``"ssim"``, the paper's, by default.
    scheme : str
        The registered inference scheme that localises the agent at each step (its belief over
        places from ``B_s``'s prediction, ``A_o`` and ``A_p``), any that accepts AIMAPP's one-factor
        sparse model (:func:`cogmap.inference.accepting`: ``"exact"``, ``"filter"``, ``"fpi"``,
        ``"vmp"``, ``"vmp_pymdp"``, ``"mmp"`` or one of yours); ``"filter"``, the exact Bayes filter
        of the paper, by default.
    mcts : cogmap.planning.mcts.MCTSConfig
        The planner's settings, used as they are (:data:`AIMAPP_MCTS`: depth 10 and 30 simulations,
        Appendix A.3 and Table 6; policy precision ``gamma`` 8, Eq. 4; a move is planned only when
        it is believed to leave the state with probability above ``move_threshold`` 0.1). In files
        (:meth:`to_dict`) its fields read ``mcts_depth``, ``mcts_simulations``, ``gamma``,
        ``min_move_probability``, ``mcts_<field>`` for the others.
    z_threshold : float
        Nats. Threshold of the confidence test (A.1.2 uses 4): the agent is confident when the
        log-odds of its most likely state against the runner-up reach it, and lost when the CUSUM
        of the observation conflict does (:mod:`cogmap.agent.confidence`).
    goal_weight : float
        Weight of the preference on the goal observation in goal mode (section 4.4).
    pose_sigma : float or None
        Metres. Width of the pose likelihood A_p and of the Eq. (7) kernel; None means
        ``influence_radius / 3`` (see :attr:`sigma`).
    obstacle_margin : float
        Metres added to ``robot_radius`` for the half-width of the collision corridor of a move
        (also passed to the simulator's own obstacle signal by :mod:`cogmap.explore`).
    inductive_threshold : float
        A transition counts as possible for the inductive term H when its probability in B_s
        exceeds this (Eq. 9, A.2); the same graph gives the path lengths of the goal study.
    inductive_depth : int
        Steps over which H propagates the goal value back (Eq. 9), beyond the MCTS depth.
    inductive_weight : float
        Weight of the inductive term in goal mode (Eq. 9).
    collision_preference : float
        Log-preference of a collision outcome (Eq. 6), read by the planner.
    prior_count : float
        Dirichlet mass of a new column: spread over the outcomes for A_o, on staying for B_s.
        Twice this marks a state whose observation column has been taught (visited).
    obs_learning_rate : float
        Counts added to A_o when an observation is tied to a state (Eq. 8; under the posterior
        when unsure between nearby states). Table 6 lists a learning rate of 1; this implementation
        uses 4, chosen so that the lost test (A.1.2) is usable.
    relocalise_ssim : float
        In [0, 1]. Without a LiDAR scan: a recognised view at least this similar re-localises the
        belief frame onto its state's stored pose.
    relocalise_align_ssim : float
        In [0, 1]. Drift correction at a revisit (section 3.3, :mod:`cogmap.agent.correction`):
        shift-searched SSIM needed against the state's anchor view (threshold measured in
        ``bench/relocalisation.py``).
    relocalise_inliers : float
        In [0, 1]. Fraction of LiDAR returns that the aligned scans must share (within 0.1 m)
        for a revisit correction, a re-localisation after being lost, or the scan check that
        tells aliasing from being lost.
    relocalise_max_shift : int
        Panorama columns searched for the heading correction (32 = 45 degrees on 256 columns).
    relocalise_max_correction : float
        In influence radii: largest position correction accepted at a revisit.
    track_anchors : bool
        At a first visit, align the scan with the anchor of the state just left.
    track_inliers : float
        In [0, 1]. Fraction of shared LiDAR returns needed for that alignment.
    track_max_correction : float
        In influence radii: largest correction that alignment (and the aliasing scan check) may
        make.
    min_correction : float
        Metres. Corrections that move the pose less than this and turn it less than
        ``min_correction_yaw`` are left out (scan alignment between places 1-2 m apart errs by
        about this much).
    min_correction_yaw : float
        Radians; see ``min_correction``.
    lost_slack : float
        Nats of conflict tolerated per step by the CUSUM lost test (:func:`cogmap.agent.confidence.cusum`);
        a conflict above it while the LiDAR scan matches the believed place counts as aliasing,
        not as evidence of being lost.
    view_weighting : bool
        Exploration that knows what the LiDAR has sensed (docs/exploration.md): weight each
        state's information gain by the unseen part of its view and pull toward informative
        states; False keeps the paper's terms only.
    view_resolution : float
        Metres: cell size of the agent's sensed grid.
    view_radius : float
        Metres: range of the view imagined from a state or frontier point (the LiDAR's).
    view_rays : int
        Rays cast for an imagined view.
    view_min_area : float
        Square metres unseen below which a state no longer promises information (also the gain
        given to states whose believed transitions the latest scan shows blocked).
    view_frontier_spacing : float
        Metres: frontier points of the sensed grid are taken one per square of this side; an
        unvisited state near one promises what its view would reveal.
    view_frontier_area : float
        Square metres that must be unseen from a frontier point for it to count.
    view_spent_radius : float
        Metres: a frontier point this close to a visited state is spent.
    view_detour : float
        Metres added to the path length when scoring a target as unseen area / (path + detour),
        as for the oracle baseline.
    view_keep_ratio : float
        Keep pursuing the current viewpoint while its score is at least this fraction of the best.
    view_keep_radius : float
        Metres: a viewpoint this close to the one pursued is taken for it.
    view_path_weight : float
        Metres of the rest of the way to a viewpoint that one metre of believed path to the
        state preferred for it is worth (the state nearest the viewpoint wins; the believed path
        breaks near-ties).
    view_tries : int
        Viewpoints considered, best first: when none of them is brought nearer by any state, no
        viewpoint is pursued and the paper's terms alone decide (the map grows around the robot).
    view_free_path : float
        Metres: an imagined view counts an unknown cell behind ``u`` metres of unknown cells with
        weight ``exp(-u / view_free_path)`` (unknown cells independently occupied; inf:
        transparent).
    view_bounds : tuple of float or None
        ``(xmin, ymin, xmax, ymax)`` of the space in the belief frame, when its outline is known
        (e.g. from a floor plan): imagined views count nothing beyond it. None (the paper's
        agent, the default): the outline is learnt from the LiDAR like everything else.
    view_doubt_range : float
        Metres: believed transitions with both ends this close to the robot are checked against
        the latest scan.
    view_floor : float
        Smallest weight of a state's information gain (fraction of a full view).
    explore_inductive_weight : float
        Weight of the inductive term toward states that still promise information while
        exploring.
    learning : cogmap.inference.learning.LearningRates
        Transition learning rates (Table 7: forward 7 / -7 / 5 / -5, reverse 5 / -5 / 3 / -3 for
        possible / impossible / predicted possible / predicted impossible).
    initial_capacity : int
        Preallocated number of states and observations of the growable model (grows past it).
    """

    num_headings: int = 12  # 12 headings + stay = 13 actions (Table 6)
    influence_radius: float = 1.0  # 1 m small environments, 2 m large ones (Table 6)
    robot_radius: float = 0.22  # physical radius: collision buffer for state creation
    node_spacing: float = 0.9  # a predicted pose is beyond a node's influence past this x radius
    lookahead_nodes: int = 8  # at most this many new states per expansion (Table 6)
    passage_width: float = 2.5  # predicted states in narrower corridors go to the centre line (0: off)
    ssim_threshold: float = 0.65  # place recognition (Table 6)
    encoder: str = "ssim"  # observation encoder by name (cogmap.agent.encoder.register_encoder)
    scheme: str = "filter"  # inference scheme by name (cogmap.inference.register); the paper's: filter
    mcts: MCTSConfig = AIMAPP_MCTS  # the planner's settings, embedded (Appendix A.3, Table 6, Eq. 4)
    z_threshold: float = 4.0  # confidence test (A.1.2), in nats of log-odds
    goal_weight: float = 10.0  # preference weight on the goal observation (section 4.4)
    pose_sigma: float | None = None  # width of the pose likelihood; default influence_radius / 3
    obstacle_margin: float = 0.1  # a direction is blocked when the sector's range < step + margin
    inductive_threshold: float = 0.5  # transitions believed possible above this (Eq. 9)
    inductive_depth: int = 60  # steps over which H propagates goal value back (beyond the MCTS depth)
    inductive_weight: float = 1.0
    collision_preference: float = -10.0  # log-preference of a collision outcome (Eq. 6), read by the planner
    prior_count: float = 0.1  # Dirichlet mass of a new column (A_o: spread over the outcomes; B_s: on staying)
    obs_learning_rate: float = 4.0  # counts added when an observation is tied to a state
    relocalise_ssim: float = 0.9  # without LiDAR: a recognised view this similar re-localises onto its state
    # drift correction by place recognition with panorama + LiDAR (thresholds from
    # bench/relocalisation.py, see cogmap.agent.correction)
    relocalise_align_ssim: float = 0.5  # shift-searched SSIM against the state's anchor view
    relocalise_inliers: float = 0.7  # fraction of LiDAR returns the aligned scans share (within 0.1 m)
    relocalise_max_shift: int = 32  # columns searched (45 degrees on a 256-column panorama)
    relocalise_max_correction: float = 0.75  # largest accepted position correction, in influence radii
    track_anchors: bool = True  # at a first visit, align the scan with the anchor of the state just left
    track_inliers: float = 0.5  # fraction of shared LiDAR returns needed for that alignment
    track_max_correction: float = 0.25  # largest correction (influence radii) it may make
    # corrections smaller than both (m, rad) are left out: scan alignment between places 1-2 m apart
    # errs by about this much, so with exact odometry they would only add noise
    min_correction: float = 0.1
    min_correction_yaw: float = 0.035
    lost_slack: float = 1.0  # nats of conflict tolerated per step by the lost test (CUSUM)
    # Exploration that knows what the LiDAR has sensed (docs/exploration.md); 0 weight: paper terms only
    view_weighting: bool = True  # weight the information gain by the unseen part of each state's view
    view_resolution: float = 0.2  # cell size of the agent's sensed grid (m)
    view_radius: float = 12.0  # range of the imagined view (m): the LiDAR's
    view_rays: int = 72
    view_free_path: float = 4.0  # m: unknown space hides what lies behind it, exp(-u / free path)
    view_min_area: float = 1.0  # m2 unseen: a state below this no longer promises information
    view_frontier_spacing: float = 1.0  # frontier points one per this square (m) when no state promises anything
    view_frontier_area: float = 4.0  # m2 unseen from a frontier point for it to count
    view_spent_radius: float = 1.0  # a frontier point this close to a visited state is spent
    view_detour: float = 1.0  # m added to the path in unseen area / (path + detour), as for the oracle
    view_keep_ratio: float = 0.7  # keep pursuing a viewpoint while its score is this close to the best
    view_keep_radius: float = 0.5  # m: a viewpoint this close to the pursued one is taken for it
    view_path_weight: float = 0.1  # m of the way left per m of believed path to the state preferred for a view
    view_tries: int = 8  # best viewpoints considered; none brought nearer: the paper's terms alone
    view_bounds: tuple[float, float, float, float] | None = None  # a known outline of the space (belief frame)
    view_doubt_range: float = 4.0  # m: believed transitions this close are checked against the latest scan
    view_floor: float = 0.05  # smallest weight of a state's information gain
    explore_inductive_weight: float = 1.0  # inductive term toward states that still promise information
    learning: LearningRates = field(default_factory=LearningRates)
    initial_capacity: int = 64

    def __post_init__(self):
        _check_values(self)
        if self.view_bounds is not None:
            object.__setattr__(self, "view_bounds", check_bounds(self.view_bounds, "AgentConfig.view_bounds"))

    @property
    def num_actions(self) -> int:
        """Number of controls: the headings plus stay (13 with the Table 6 default)."""
        return self.num_headings + 1

    @property
    def stay(self) -> int:
        """The stay control is the last one."""
        return self.num_headings

    @property
    def sigma(self) -> float:
        """Width (m) of the pose likelihood: ``pose_sigma``, or ``influence_radius / 3`` when unset."""
        return self.pose_sigma if self.pose_sigma is not None else self.influence_radius / 3

    def to_dict(self) -> dict:
        """Every field as plain data (the learning rates as a nested dict), for manifests and JSON.

        Returns
        -------
        dict
            Field name -> value; ``encoder`` is left out when it is the default ``"ssim"``,
            ``scheme`` when it is ``"filter"`` and
            ``view_bounds`` when None (so manifests and study run keys made before these fields
            existed stay the same; :meth:`from_dict` restores them).
        """
        return _to_dict(self)

    @classmethod
    def from_dict(cls, d: dict) -> AgentConfig:
        """The inverse of :meth:`to_dict` (also after a JSON round trip).

        Parameters
        ----------
        d : dict
            Field name -> value, e.g. from :meth:`to_dict` or a run manifest; missing fields take
            their defaults; ``learning`` may be a dict (lists become tuples).

        Returns
        -------
        AgentConfig
            The configuration, every field kept, the nested learning rates included.

        Raises
        ------
        ValueError
            On a key that is not a field (of the config or of the learning rates), or a
            ``scheme`` that names no registered inference scheme.
        """
        return cls(**_from_dict(d))


def _to_dict(cfg) -> dict:
    """``cfg`` as plain data (see ``AgentConfig.to_dict``)."""
    d = asdict(cfg)
    del d["mcts"]
    for f in fields(MCTSConfig):  # the planner's settings, flat as in files made before they were nested
        key, v = _MCTS_KEYS.get(f.name, f"mcts_{f.name}"), getattr(cfg.mcts, f.name)
        if f.name in _MCTS_KEYS or v != getattr(_MCTS_DEFAULT, f.name):
            d[key] = v
    if d["view_bounds"] is None:  # likewise: runs that know no outline keep their keys
        del d["view_bounds"]
    if d["scheme"] == "filter":  # the paper's scheme is implicit too: earlier run keys stay valid
        del d["scheme"]
    if d["encoder"] == "ssim":
        # the paper's encoder is left implicit (from_dict restores it), so the manifests and
        # study run keys of runs made before encoders were chosen by name stay the same
        del d["encoder"]
    return d


def _from_dict(d: dict) -> dict:
    """The keyword arguments of :class:`AgentConfig` from a file's dict (see ``from_dict``)."""
    d = dict(d)
    for key in _RETIRED & set(d):  # settings of earlier versions that no longer change a run
        warnings.warn(f"AgentConfig: field {key!r} is retired and ignored", stacklevel=3)
        del d[key]
    mcts = {f.name: d.pop(_MCTS_KEYS.get(f.name, f"mcts_{f.name}")) for f in fields(MCTSConfig)
            if _MCTS_KEYS.get(f.name, f"mcts_{f.name}") in d}
    _check_keys(AgentConfig, d)
    if isinstance(d.get("mcts"), dict):  # nested, as asdict writes it
        _check_keys(MCTSConfig, d["mcts"])
        mcts = d.pop("mcts") | mcts
    if mcts:
        d["mcts"] = MCTSConfig(**{f.name: getattr(AIMAPP_MCTS, f.name) for f in fields(MCTSConfig)} | mcts)
    if isinstance(d.get("learning"), dict):
        lr = dict(d["learning"])
        _check_keys(LearningRates, lr)
        d["learning"] = LearningRates(**{k: tuple(v) if isinstance(v, list) else v for k, v in lr.items()})
    if "scheme" in d:  # a name read from a file only selects among the schemes registered in this process
        from cogmap import inference

        if d["scheme"] not in inference.available():
            raise ValueError(f"AgentConfig.scheme: {d['scheme']!r} is not a registered inference scheme "
                             f"(registered: {', '.join(inference.available())}; add yours with --plugin)")
    return d


_RETIRED = frozenset({"view_frontier_reach"})


def _number(v) -> bool:
    import numpy as np

    return not isinstance(v, bool | np.bool_) and isinstance(v, int | float | np.integer | np.floating)


def _bad(name: str, v, expected: str):
    raise ValueError(f"AgentConfig.{name}: expected {expected}, got {v!r}")


def _check_one(v, kind: str, name: str) -> None:
    """Refuse ``v`` unless it is of the field's ``kind`` (bool, int, float, optional float, str)."""
    import math

    import numpy as np

    if kind == "bool":
        if not isinstance(v, bool | np.bool_):
            _bad(name, v, "true or false")
    elif kind == "int":
        if isinstance(v, bool | np.bool_) or not isinstance(v, int | np.integer):
            _bad(name, v, "an integer")
    elif kind in ("float", "float | None"):
        if v is None and kind == "float | None":
            return
        if not _number(v) or not math.isfinite(v):
            _bad(name, v, "a finite number" + (" or None" if kind != "float" else ""))
    elif kind == "str":
        if not isinstance(v, str):
            _bad(name, v, "a string")
        if name in ("scheme", "encoder") and not v:
            _bad(name, v, "a non-empty string")


def _check_values(cfg) -> None:
    """Refuse a field of the wrong type or a non-finite number, naming the field (``AgentConfig.x``);
    the nested learning rates too (``AgentConfig.learning.x``), and the MCTS settings by their names
    in files (``AgentConfig.mcts_depth``, ``AgentConfig.gamma``, ...)."""
    import math

    for f in fields(cfg):
        v, name = getattr(cfg, f.name), f.name
        if name == "view_bounds":
            continue  # checked by check_bounds
        if name == "mcts":
            if not isinstance(v, MCTSConfig):
                _bad(name, v, "MCTSConfig")
            for g in fields(v):
                if str(g.type) in ("bool", "int", "float"):
                    _check_one(getattr(v, g.name), str(g.type), _MCTS_KEYS.get(g.name, f"mcts_{g.name}"))
        elif name == "learning":
            if not isinstance(v, LearningRates):
                _bad(name, v, "LearningRates")
            for g in fields(v):
                w = getattr(v, g.name)
                items = w if isinstance(w, tuple) else (w,)
                if not items or not all(_number(x) and math.isfinite(x) for x in items):
                    _bad(f"learning.{g.name}", w, "finite numbers" if isinstance(w, tuple) else "a finite number")
        else:
            _check_one(v, str(f.type), name)


def _check_keys(cls, d: dict) -> None:
    unknown = sorted(set(d) - {f.name for f in fields(cls)})
    if unknown:
        raise ValueError(f"{cls.__name__}: unknown field(s) {', '.join(map(repr, unknown))}")

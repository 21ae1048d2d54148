"""Every AIMAPP parameter in one place, with the paper's defaults (Table 6, A.1, Table 7)."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field, fields

from cogmap.inference.learning import LearningRates


@dataclass(frozen=True)
class AgentConfig:
    num_headings: int = 12  # 12 headings + stay = 13 actions (Table 6)
    influence_radius: float = 1.0  # 1 m small environments, 2 m large ones (Table 6)
    robot_radius: float = 0.22  # physical radius: collision buffer for state creation
    node_spacing: float = 0.9  # a predicted pose is beyond a node's influence past this x radius
    lookahead_nodes: int = 8  # at most this many new states per expansion (Table 6)
    ssim_threshold: float = 0.65  # place recognition (Table 6)
    encoder: str = "ssim"  # observation encoder by name (cogmap.agent.encoder.register_encoder)
    mcts_depth: int = 10  # Appendix A.3
    mcts_simulations: int = 30
    mcts_count_information_once: bool = False  # Eq. 5 sums every step's EFE (see MCTSConfig)
    mcts_discount: float = 1.0
    z_threshold: float = 4.0  # confidence test (A.1.2), in nats of log-odds
    goal_weight: float = 10.0  # preference weight on the goal observation (section 4.4)
    gamma: float = 8.0  # policy precision (Eq. 4)
    pose_sigma: float | None = None  # width of the pose likelihood; default influence_radius / 3
    obstacle_margin: float = 0.1  # a direction is blocked when the sector's range < step + margin
    min_move_probability: float = 0.1  # a move is planned only if it is believed to leave the state
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
    view_radius: float = 6.0  # range of the imagined view from a state (m)
    view_rays: int = 48
    view_min_area: float = 1.0  # m2 unseen: a state below this no longer promises information
    view_frontier_spacing: float = 1.0  # frontier points one per this square (m) when no state promises anything
    view_frontier_area: float = 4.0  # m2 unseen from a frontier point for it to count
    view_spent_radius: float = 1.5  # a frontier point this close to a visited state is spent
    view_frontier_reach: float = 6.0  # m: a frontier point counts for an unvisited state that sees it this close
    view_detour: float = 1.0  # m added to the path in unseen area / (path + detour), as for the oracle
    view_keep_ratio: float = 0.7  # keep pursuing a target while its score is this close to the best
    view_doubt_range: float = 4.0  # m: believed transitions this close are checked against the latest scan
    view_floor: float = 0.05  # smallest weight of a state's information gain
    explore_inductive_weight: float = 1.0  # inductive term toward states that still promise information
    learning: LearningRates = field(default_factory=LearningRates)
    initial_capacity: int = 64

    @property
    def num_actions(self) -> int:
        return self.num_headings + 1

    @property
    def stay(self) -> int:
        """The stay control is the last one."""
        return self.num_headings

    @property
    def sigma(self) -> float:
        return self.pose_sigma if self.pose_sigma is not None else self.influence_radius / 3

    def to_dict(self) -> dict:
        d = asdict(self)
        if d["encoder"] == "ssim":
            # the paper's encoder is left implicit (from_dict restores it), so the manifests and
            # study run keys of runs made before encoders were chosen by name stay the same
            del d["encoder"]
        return d

    @classmethod
    def from_dict(cls, d: dict) -> AgentConfig:
        """The inverse of :meth:`to_dict` (also after a JSON round trip): every field is kept,
        the nested learning rates included; an unknown key is a clear error."""
        d = dict(d)
        _check_keys(cls, d)
        if isinstance(d.get("learning"), dict):
            lr = dict(d["learning"])
            _check_keys(LearningRates, lr)
            d["learning"] = LearningRates(**{k: tuple(v) if isinstance(v, list) else v for k, v in lr.items()})
        return cls(**d)


def _check_keys(cls, d: dict) -> None:
    unknown = sorted(set(d) - {f.name for f in fields(cls)})
    if unknown:
        raise ValueError(f"{cls.__name__}: unknown field(s) {', '.join(map(repr, unknown))}")

"""`DroneAgent`: the stateful shell that wires perception, kernel beliefs and the waypoint planner.

Per decision (as the published planning server): sense (voxels, clearance d_obs, density rho,
suitability S), update the kernel beliefs over (distance, azimuth, elevation, suitability, density)
with the ``"kernel"`` scheme (re-initialised on every call by default, as published; persistent with
``persistent_beliefs=True``), plan candidates and rank them, and return the first action. The agent
holds state (voxel memory, beliefs, RNG) and no maths.
"""

from __future__ import annotations

import time
from collections import deque
from dataclasses import dataclass, field

import numpy as np

from cogmap import inference
from cogmap.genmodel.drone_beliefs import (
    KernelBeliefModel,
    egocentric_state,
    entropy,
    expected_state,
    normalised_entropy,
)
from cogmap.genmodel.suitability import MIN_POINTS, VOXEL_SIZE, clearance, density, suitability, voxelise
from cogmap.planning.drone_efe import drone_objective
from cogmap.planning.drone_planner import DronePlannerConfig, DroneScene, PlanResult
from cogmap.planning.planners import PlanSettings, get_planner

SENSE_RADIUS = 20.0  # the LiDAR's range: only voxels this close describe the current state


class VoxelMap:
    """Obstacle voxels (0.15 m) of the last ``memory`` LiDAR scans.

    ``memory=1`` is the original's per-scan view. With 400 rays a single sweep leaves 14.4 deg between
    azimuths (1.3 m at 5 m range, enough to miss a trunk), and each scan turns the pattern by a
    golden-ratio fraction of that spacing, so a short memory of recent scans (default 12, the scans
    of about 2-3 planning steps with the in-flight ones) fills the gaps while keeping the voxel count,
    and so the planning time, bounded. Voxels seen in several scans count once.

    Parameters
    ----------
    voxel : float, optional
        Voxel side, metres.
    min_points : int, optional
        Hits a voxel needs to count as an obstacle.
    memory : int, optional
        Number of recent scans kept, at least 1; default 12.

    Raises
    ------
    ValueError
        If ``memory < 1``.
    """

    def __init__(self, voxel: float = VOXEL_SIZE, min_points: int = MIN_POINTS, memory: int = 12):
        if memory < 1:
            raise ValueError(f"VoxelMap: memory must be >= 1 scan, got {memory}")
        self.voxel, self.min_points = voxel, min_points
        self.scans: deque = deque(maxlen=memory)
        self._points = None

    def add(self, hits) -> None:
        """Add one scan's hit points (the oldest scan is forgotten when ``memory`` is full).

        Parameters
        ----------
        hits : array_like
            ``(N, 3)`` float hit points, metres, world frame.
        """
        self.scans.append(np.asarray(hits, float).reshape(-1, 3))
        self._points = None

    @property
    def points(self) -> np.ndarray:
        """``(V, 3)`` float obstacle voxels of the remembered scans (computed on first access)."""
        if self._points is None:
            pts = np.vstack(list(self.scans)) if self.scans else np.zeros((0, 3))
            self._points = voxelise(pts, self.voxel, self.min_points)
        return self._points

    def near(self, position, radius: float = SENSE_RADIUS) -> np.ndarray:
        """Voxels within ``radius`` of ``position``.

        Parameters
        ----------
        position : array_like
            ``(3,)`` metres.
        radius : float, optional
            Metres; default the LiDAR range (20 m).

        Returns
        -------
        numpy.ndarray
            ``(k, 3)`` float voxels.
        """
        P = self.points
        if len(P) == 0:
            return P
        return P[((P - np.asarray(position, float)) ** 2).sum(1) <= radius * radius]


@dataclass(frozen=True)
class DroneAgentConfig:
    """Settings of :class:`DroneAgent`.

    Attributes
    ----------
    planner : DronePlannerConfig
        Waypoint generation, filtering and EFE ranking settings.
    persistent_beliefs : bool
        False (default): per-call re-initialisation of the kernel beliefs, as published.
    scan_memory : int
        LiDAR scans whose voxels describe the surroundings (1: per scan), default 12.
    replan_distance : float
        Replan when an obstacle comes within this many metres in flight.
    near_goal : float
        Slow down within this distance (metres) of the target.
    dense : float
        ... or when the density exceeds this.
    depth : int
        1: the paper's one-step ranking; 2 or 3: EFE over waypoint sequences (beyond the paper).
    contact_memory : bool
        True (default): the touched point of every collision stays an obstacle voxel for the rest
        of the episode (a contact is an observation; the LiDAR's +-10 deg fan misses obstacles just
        above or below the drone). False: contacts are not perceived, as published.
    """
    planner: DronePlannerConfig = field(default_factory=DronePlannerConfig)
    persistent_beliefs: bool = False  # False: per-call re-initialisation, as published
    scan_memory: int = 12  # LiDAR scans whose voxels describe the surroundings (1: per-scan)
    replan_distance: float = 2.0  # replan when an obstacle comes within this in flight
    near_goal: float = 10.0  # slow down within this distance of the target
    dense: float = 0.1  # ... or when the density exceeds this
    depth: int = 1  # 1: the paper's one-step ranking; 2 or 3: EFE over waypoint sequences (beyond the paper)
    contact_memory: bool = True  # False: collisions are not perceived, as published

    @classmethod
    def published(cls, **changes) -> DroneAgentConfig:
        """The published agent: :meth:`DronePlannerConfig.published` and no contact memory.

        Parameters
        ----------
        **changes
            Further fields to set.

        Returns
        -------
        DroneAgentConfig
        """
        return cls(**{"planner": DronePlannerConfig.published(), "contact_memory": False, **changes})

    def to_dict(self) -> dict:
        """The settings as a nested dict (for run records).

        Returns
        -------
        dict
        """
        from dataclasses import asdict

        return asdict(self)


@dataclass
class Decision:
    waypoint: np.ndarray
    speed: float
    plan: PlanResult
    plan_ms: float  # wall-clock of the whole planning call (beliefs + candidates + EFE + ranking)
    state: dict  # d_obs, rho, S, expected state, entropies


class DronePolicy:
    """What an episode (:func:`cogmap.drone.episode.fly_episode`) calls on a drone policy:
    ``reset``, ``observe`` (every LiDAR scan, also those taken in flight), ``observe_contact``,
    ``decide``. By default a policy perceives LiDAR returns only and keeps them in its voxel map
    when it has one (``voxels``); ``decide`` is each policy's own.
    """

    replans_in_flight = False
    voxels: VoxelMap | None = None

    def reset(self, target=None, start=None) -> None:
        """Start an episode (nothing to forget by default).

        Parameters
        ----------
        target : array_like, optional
            ``(3,)`` target position, metres.
        start : array_like, optional
            ``(3,)`` start position, metres.
        """

    def observe(self, scan, position=None) -> None:
        """Add a LiDAR scan to the voxel memory (ignored by a policy without one).

        Parameters
        ----------
        scan : object
            A LiDAR scan with ``points``, ``(N, 3)`` float hit points in metres, world frame.
        position : array_like, optional
            Where the scan was taken (unused).
        """
        if self.voxels is not None:
            self.voxels.add(scan.points)

    def observe_contact(self, point) -> None:
        """Ignore a collision's touched point (the default: LiDAR returns only).

        Parameters
        ----------
        point : array_like
            ``(3,)`` the touched point, metres, world frame (unused).
        """

    def decide(self, position, target) -> Decision:  # pragma: no cover - each policy's own
        """The next waypoint and speed.

        Parameters
        ----------
        position : array_like
            ``(3,)`` current position, metres, world frame.
        target : array_like
            ``(3,)`` target position, metres.

        Returns
        -------
        Decision
        """
        raise NotImplementedError


class DroneAgent(DronePolicy):
    """The drone's stateful shell: voxel memory, kernel beliefs, RNG; the maths lives in the libraries.

    ``observe(scan)`` feeds LiDAR sweeps (also those taken in flight); ``decide(position, target)``
    returns a :class:`Decision`.

    Parameters
    ----------
    config : DroneAgentConfig, optional
        Settings; default ``DroneAgentConfig()``.
    seed : int, optional
        Seed of the planner's random candidates, default 0.
    speeds : tuple of float, optional
        ``(cruise, slow)`` speeds in m/s, default ``(2.0, 1.5)``.
    """

    replans_in_flight = True

    def __init__(self, config: DroneAgentConfig | None = None, seed: int = 0, speeds=(2.0, 1.5)):
        self.config = config or DroneAgentConfig()
        self.model = KernelBeliefModel()
        self.scheme = inference.get("kernel")
        self.planner = get_planner("drone")
        self.objective = drone_objective(self.config.planner.w_pragmatic, self.config.planner.w_epistemic)
        self.rng = np.random.default_rng(seed)
        self.speeds = speeds
        self.reset()

    def settings(self) -> dict:
        """The agent's settings (for run records and run keys): its config and speeds.

        Returns
        -------
        dict
        """
        return {"policy": "agent", **self.config.to_dict(), "speeds": list(self.speeds)}

    def reset(self, target=None, start=None) -> None:
        """Start an episode: empty voxel memory, visits, contacts and beliefs; remember the
        start-to-target distance if given.

        Parameters
        ----------
        target : array_like, optional
            ``(3,)`` target position, metres.
        start : array_like, optional
            ``(3,)`` start position, metres.
        """
        self.voxels = VoxelMap(memory=self.config.scan_memory)
        self.beliefs = None
        self.visited: list[np.ndarray] = []  # positions of the episode's earlier decisions
        self.contacts: list[np.ndarray] = []  # touched points of the episode's collisions
        self.d_start = None
        if target is not None and start is not None:
            self.d_start = float(np.linalg.norm(np.asarray(target, float) - np.asarray(start, float)))

    def observe_contact(self, point) -> None:
        """Remember the touched point of a collision as an obstacle voxel (with ``contact_memory``).

        Parameters
        ----------
        point : array_like
            ``(3,)`` the touched point, metres, world frame.
        """
        if self.config.contact_memory and point is not None:
            self.contacts.append(np.asarray(point, float).reshape(3).copy())

    def sense(self, position) -> tuple[np.ndarray, float, float, float]:
        """What the drone perceives at ``position``.

        Parameters
        ----------
        position : array_like
            ``(3,)`` metres.

        Returns
        -------
        voxels : numpy.ndarray
            ``(k, 3)`` float voxels within the LiDAR range (remembered contacts included).
        d_obs : float
            Clearance to the nearest voxel, metres.
        rho : float
            Obstacle density.
        S : float
            Suitability in [0, 1] (DRONE.md formula).
        """
        V = self.voxels.near(position)
        if self.contacts:
            C = np.array(self.contacts)
            C = C[((C - np.asarray(position, float)) ** 2).sum(1) <= SENSE_RADIUS ** 2]
            V = np.vstack([V, C]) if len(C) else V
        d_obs = clearance(position, V)
        rho = density(position, V)
        return V, d_obs, rho, float(suitability(d_obs, rho))

    def decide(self, position, target) -> Decision:
        """Sense, update the kernel beliefs, plan and rank candidate waypoints; return the first action.

        Slows down near the target or in dense clutter.

        Parameters
        ----------
        position : array_like
            ``(3,)`` current position, metres, world frame.
        target : array_like
            ``(3,)`` target position, metres.

        Returns
        -------
        Decision
            ``waypoint`` (``(3,)`` metres), ``speed`` (m/s), ``plan``, ``plan_ms`` and ``state``.
        """
        pos = np.asarray(position, float)
        tgt = np.asarray(target, float)
        if self.d_start is None:
            self.d_start = float(np.linalg.norm(tgt - pos))
        V, d_obs, rho, S = self.sense(pos)
        # the planning call, timed as the original's server round trip: beliefs, candidates,
        # per-waypoint suitability, filter, EFE, ranking (perception ran on the client before)
        t0 = time.perf_counter()
        # moveToPositionAsync keeps the take-off yaw, so the egocentric frame is the world frame
        obs = {**egocentric_state(pos, tgt, 0.0), "suitability": S, "density": min(rho, 1.0)}
        prior = self.beliefs if self.config.persistent_beliefs else None
        beliefs, _ = self.scheme(self.model, prior, [obs])
        self.beliefs = beliefs
        H = [entropy(b) for b in beliefs]
        scene = DroneScene(pos, tgt, V, d_obs, rho, S, self.d_start, np.array(self.visited).reshape(-1, 3),
                           self.config.planner)
        settings = PlanSettings(policy_len=self.config.depth, rng=self.rng)
        plan = self.planner(scene, beliefs, self.objective, settings).info
        plan_ms = 1e3 * (time.perf_counter() - t0)
        self.visited.append(pos.copy())
        d_tgt = float(np.linalg.norm(tgt - pos))
        slow = d_tgt < self.config.near_goal or rho > self.config.dense
        expected = expected_state(self.model, beliefs)
        scale = 1.0 - 0.5 * (normalised_entropy(self.model, beliefs, "distance")
                             + normalised_entropy(self.model, beliefs, "azimuth"))
        state = {"d_obs": d_obs, "rho": rho, "S": S, "expected_distance": expected["distance"],
                 "expected_suitability": expected["suitability"] * scale, "entropy_sum": H[0] + H[1] + H[2]}
        return Decision(plan.actions[0], self.speeds[1] if slow else self.speeds[0], plan, plan_ms, state)

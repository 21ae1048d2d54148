"""`DroneAgent`: the stateful shell that wires perception, kernel beliefs and the waypoint planner.

Per decision (as the published planning server): sense (voxels, clearance d_obs, density rho,
suitability S), update the kernel beliefs over (distance, azimuth, elevation, suitability, density)
with the ``"kernel"`` scheme (re-initialised on every call by default, as published; persistent with
``persistent_beliefs=True``), plan candidates and rank them, and return the first action. The agent
holds state (voxel memory, beliefs, RNG) and no maths.
"""

from __future__ import annotations

import time
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
from cogmap.genmodel.suitability import clearance, density, suitability
from cogmap.genmodel.voxel_map import SENSE_RADIUS, VoxelMap
from cogmap.planning.drone_efe import drone_objective
from cogmap.planning.drone_planner import DronePlannerConfig, DroneScene
from cogmap.planning.drone_policies import Decision, DronePolicy
from cogmap.planning.planners import PlanSettings, get_planner


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


class DroneAgent(DronePolicy):
    """The drone's stateful shell: voxel memory, kernel beliefs, RNG; the maths lives in the libraries.

    ``observe(scan)`` feeds LiDAR sweeps (also those taken in flight); ``decide(position, target)``
    senses, updates the kernel beliefs, plans and ranks candidate waypoints through the planner
    ``"drone"`` and returns the first action as a :class:`Decision`, slowing down near the target or
    in dense clutter.

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
        target, start : array_like, optional
            As in :meth:`cogmap.planning.drone_policies.DronePolicy.reset`.
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

    def decide(self, position, target) -> Decision:  # documented in DronePolicy.decide
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
        beliefs, _ = inference.get("kernel")(self.model, prior, [obs])
        self.beliefs = beliefs
        H = [entropy(b) for b in beliefs]
        scene = DroneScene(pos, tgt, V, d_obs, rho, S, self.d_start, np.array(self.visited).reshape(-1, 3),
                           self.config.planner)
        settings = PlanSettings(policy_len=self.config.depth, rng=self.rng)
        objective = drone_objective(self.config.planner.w_pragmatic, self.config.planner.w_epistemic)
        plan = get_planner("drone")(scene, beliefs, objective, settings).info
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

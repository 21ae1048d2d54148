"""Drone policies: what an episode calls on one (:class:`DronePolicy`), the :class:`Decision` it
returns, and two baselines: straight-line flight and a potential field over the sensed voxels."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cogmap.genmodel.voxel_map import VoxelMap

from .drone_planner import PlanResult


@dataclass
class Decision:
    waypoint: np.ndarray
    speed: float
    plan: PlanResult
    plan_ms: float  # wall-clock of the whole planning call (beliefs + candidates + EFE + ranking)
    state: dict  # d_obs, rho, S, expected state, entropies


class DronePolicy:
    """What a drone episode (:func:`cogmap.envs.drone_episode.fly_episode`) calls on a drone policy:
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



@dataclass
class _Plan:
    rule: str = "baseline"
    efe_us_per_candidate: float = float("nan")


class StraightLine(DronePolicy):
    """Fly toward the target in steps of ``step`` metres (to the target itself when closer), blind to
    obstacles.

    Parameters
    ----------
    step : float, optional
        Metres per decision, default 3.
    speeds : tuple of float, optional
        ``(cruise, slow)`` m/s; slow within 10 m of the target.
    """

    replans_in_flight = False

    def __init__(self, step: float = 3.0, speeds=(2.0, 1.5)):
        self.step, self.speeds = step, speeds

    def settings(self) -> dict:
        """The baseline's parameters (for run records and run keys).

        Returns
        -------
        dict
        """
        return {"policy": "straight", "step": self.step, "speeds": list(self.speeds)}

    def decide(self, position, target) -> Decision:  # documented in DronePolicy.decide
        pos, tgt = np.asarray(position, float), np.asarray(target, float)
        d = tgt - pos
        n = float(np.linalg.norm(d))
        wp = tgt.copy() if n <= self.step else pos + self.step * d / n
        return Decision(wp, self.speeds[1] if n < 10 else self.speeds[0], _Plan("straight"), 0.0, {})


class PotentialField(DronePolicy):
    """Attraction to the target plus repulsion from voxels within ``influence`` metres; each decision
    is one step along the summed force.

    Repulsion ``k_rep (1/d - 1/influence) / d^2`` along the away direction; one step of ``step``
    metres along the resulting force; a floor keeps it above ``min_altitude``.

    Parameters
    ----------
    step : float, optional
        Metres per decision, default 2.
    influence : float, optional
        Repulsion radius, metres, default 5.
    k_att : float, optional
        Attraction gain, default 1.
    k_rep : float, optional
        Repulsion gain, default 4.
    min_altitude : float, optional
        Lowest waypoint altitude, metres, default 1.
    speeds : tuple of float, optional
        ``(cruise, slow)`` m/s; slow within 10 m of the target.
    """

    replans_in_flight = False

    def __init__(self, step: float = 2.0, influence: float = 5.0, k_att: float = 1.0, k_rep: float = 4.0,
                 min_altitude: float = 1.0, speeds=(2.0, 1.5)):
        self.step, self.influence, self.k_att, self.k_rep = step, influence, k_att, k_rep
        self.min_altitude, self.speeds = min_altitude, speeds
        self.voxels = VoxelMap()

    def settings(self) -> dict:
        """The baseline's parameters (for run records and run keys).

        Returns
        -------
        dict
        """
        return {"policy": "potential", "step": self.step, "influence": self.influence, "k_att": self.k_att,
                "k_rep": self.k_rep, "min_altitude": self.min_altitude, "speeds": list(self.speeds),
                "scan_memory": self.voxels.scans.maxlen}

    def reset(self, target=None, start=None) -> None:
        """Forget the sensed voxels.

        Parameters
        ----------
        target, start : array_like, optional
            As in :meth:`DronePolicy.reset`.
        """
        self.voxels = VoxelMap()

    def decide(self, position, target) -> Decision:  # documented in DronePolicy.decide
        pos, tgt = np.asarray(position, float), np.asarray(target, float)
        d = tgt - pos
        n = float(np.linalg.norm(d))
        force = self.k_att * d / max(n, 1e-9)
        V = self.voxels.near(pos, self.influence)
        if len(V):
            away = pos - V
            dist = np.maximum(np.linalg.norm(away, axis=1), 0.05)
            mag = self.k_rep * (1.0 / dist - 1.0 / self.influence) / dist ** 2
            force = force + (mag[:, None] * away / dist[:, None]).sum(0)
        f = float(np.linalg.norm(force))
        step = min(self.step, n)
        wp = pos + step * force / max(f, 1e-9)
        wp[2] = max(wp[2], self.min_altitude)
        return Decision(wp, self.speeds[1] if n < 10 else self.speeds[0], _Plan("potential"), 0.0, {})

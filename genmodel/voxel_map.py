"""The drone's obstacle memory: voxels of its last LiDAR scans (DRONE.md 2.2)."""

from __future__ import annotations

from collections import deque

import numpy as np

from .suitability import MIN_POINTS, VOXEL_SIZE, voxelise

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

"""Sensor helpers independent of pybullet: beam angles, obstacle signal, fault schedules."""

from __future__ import annotations

import numpy as np

STREAMS = ("lidar", "camera", "odometry")


def lidar_angles(n_beams: int) -> np.ndarray:
    """Beam angles in the robot frame: beam 0 points forward, counter-clockwise."""
    return np.arange(n_beams) * (2 * np.pi / n_beams)


def obstacle_signal(ranges: np.ndarray, beam_headings: np.ndarray, n_dirs: int,
                    threshold: float) -> np.ndarray:
    """Binary obstacle flag per action direction (1 = blocked).

    Direction k covers headings within half a sector of k * 2 pi / n_dirs (same frame as
    `beam_headings`); it is blocked when the minimum range in that sector is below
    `threshold` (robot radius + step length + margin). Minimum, not mean.
    """
    width = 2 * np.pi / n_dirs
    sector = np.floor(((beam_headings + width / 2) % (2 * np.pi)) / width).astype(int) % n_dirs
    mins = np.full(n_dirs, np.inf)
    np.minimum.at(mins, sector, ranges)
    return (mins < threshold).astype(np.int8)


class FaultSchedule:
    """Dropout windows per stream: `stream` gives no data for steps in [start, start + length)."""

    def __init__(self):
        self.windows: dict[str, list[tuple[int, int]]] = {s: [] for s in STREAMS}

    def add(self, stream: str, start_step: int, length: int) -> None:
        if stream not in self.windows:
            raise ValueError(f"unknown stream {stream!r}; known: {STREAMS}")
        if length < 0 or start_step < 0:
            raise ValueError("start_step and length must be non-negative")
        self.windows[stream].append((int(start_step), int(start_step) + int(length)))

    def dropped(self, stream: str, step: int) -> bool:
        return any(a <= step < b for a, b in self.windows[stream])

    def clear(self) -> None:
        for v in self.windows.values():
            v.clear()


class FaultInjection:
    """Sensor dropouts for a simulator that keeps a :class:`FaultSchedule` as ``faults``."""

    faults: FaultSchedule

    def inject_fault(self, stream: str, start_step: int, length: int) -> None:
        """Drop a sensor stream for steps ``[start_step, start_step + length)``.

        Parameters
        ----------
        stream : str
            ``"lidar"``, ``"camera"`` or ``"odometry"``.
        start_step : int
            First step without data.
        length : int
            Number of steps without data.
        """
        self.faults.add(stream, start_step, length)

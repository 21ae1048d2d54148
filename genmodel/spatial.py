"""A grid hash over stored 2-D poses: the states near a point without scanning the map.

Cells are squares of side ``cell``; each holds the indices of the poses inside it. A query
reads the cells its disc overlaps, so its cost depends on how many poses lie near the point,
not on how many the map holds. Poses are only added (stored poses of a map never move).
"""

from __future__ import annotations

import math

import numpy as np


class PoseIndex:
    """Indices of points ``poses[i]`` (kept by the caller) hashed by grid cell."""

    def __init__(self, poses: np.ndarray, cell: float, count: int = 0):
        if not cell > 0:
            raise ValueError(f"cell size must be positive, got {cell}")
        self.cell = float(cell)
        self.poses = poses  # (capacity, 2), rows [0, count) indexed; the owner may reallocate it
        self.cells: dict[tuple[int, int], list[int]] = {}
        self.count = 0
        self.lo = [math.inf, math.inf]  # bounding box of occupied cells
        self.hi = [-math.inf, -math.inf]
        for i in range(count):
            self.add(i)

    def _key(self, xy) -> tuple[int, int]:
        return math.floor(xy[0] / self.cell), math.floor(xy[1] / self.cell)

    def add(self, i: int) -> None:
        """Index row ``i`` of ``poses`` (rows are added in order)."""
        key = self._key(self.poses[i])
        self.cells.setdefault(key, []).append(i)
        self.count = max(self.count, i + 1)
        for a in (0, 1):
            self.lo[a] = min(self.lo[a], key[a])
            self.hi[a] = max(self.hi[a], key[a])

    def _ring(self, cx: int, cy: int, k: int) -> list[int]:
        """Indices in the cells at Chebyshev distance ``k`` from cell (cx, cy)."""
        out: list[int] = []
        cells = self.cells
        if k == 0:
            return list(cells.get((cx, cy), ()))
        for x in range(cx - k, cx + k + 1):
            out.extend(cells.get((x, cy - k), ()))
            out.extend(cells.get((x, cy + k), ()))
        for y in range(cy - k + 1, cy + k):
            out.extend(cells.get((cx - k, y), ()))
            out.extend(cells.get((cx + k, y), ()))
        return out

    def near(self, xy, radius: float) -> tuple[np.ndarray, np.ndarray]:
        """Indices of the poses within ``radius`` of ``xy`` and their distances."""
        xy = np.asarray(xy, dtype=float)
        cx, cy = self._key(xy)
        reach = int(math.ceil(radius / self.cell))
        idx: list[int] = []
        for x in range(cx - reach, cx + reach + 1):
            for y in range(cy - reach, cy + reach + 1):
                idx.extend(self.cells.get((x, y), ()))
        idx_arr = np.asarray(idx, dtype=np.int64)
        if idx_arr.size == 0:
            return idx_arr, np.zeros(0)
        idx_arr.sort()  # in index order, like a scan of the whole map
        d = np.hypot(*(self.poses[idx_arr] - xy).T)
        keep = d <= radius
        return idx_arr[keep], d[keep]

    def nearest(self, xy) -> tuple[int, float]:
        """The nearest indexed pose to ``xy`` and its distance ((-1, inf) when empty; ties go to
        the lowest index): rings of cells are read outward until no unread cell can hold a
        pose as close."""
        if self.count == 0:
            return -1, math.inf
        xy = np.asarray(xy, dtype=float)
        cx, cy = self._key(xy)
        best, best_d = -1, math.inf
        k = 0
        while True:
            idx = self._ring(cx, cy, k)
            if idx:
                idx_arr = np.sort(np.asarray(idx, dtype=np.int64))
                d = np.hypot(*(self.poses[idx_arr] - xy).T)
                j = int(np.argmin(d))
                if d[j] < best_d or (d[j] == best_d and idx_arr[j] < best):  # ties: lowest index
                    best, best_d = int(idx_arr[j]), float(d[j])
            # every pose in ring k + 1 or beyond is at least k * cell away
            if best >= 0 and best_d < k * self.cell:
                return best, best_d
            k += 1
            if k > 2 + self._max_ring(cx, cy):
                return best, best_d

    def _max_ring(self, cx: int, cy: int) -> int:
        """Chebyshev distance (in cells) from (cx, cy) to the farthest occupied cell."""
        lo, hi = self.lo, self.hi
        return int(max(abs(cx - lo[0]), abs(cx - hi[0]), abs(cy - lo[1]), abs(cy - hi[1])))

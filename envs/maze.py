"""Seeded random square mazes for the DVBF-LM experiments (paper Appendix A-A, Table II).

A maze is an ``n x n`` grid of square cells filling ``[0, size]^2``; walls lie on cell borders.
The layout is a perfect maze (randomised depth-first search) from which a seeded fraction of
inner walls is removed, which opens loops and small rooms. Complexity fixes the number of cells
per side, corridor width the cell side, and so the maze size (Table II):

============  ======  ==========  ============  ===========
complexity    cells   small       medium        large
============  ======  ==========  ============  ===========
simple        3       0.25        0.5           0.75
moderate      6       0.5         1.0           1.5
complex       12      1.0         2.0           3.0
============  ======  ==========  ============  ===========

The SLAM mazes of the paper fill the unit square: ``moderate`` / ``medium`` (6 x 6 cells of
side 1/6). Pure numpy; the pybullet world is in :mod:`cogmap.envs.maze_sim`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

CELLS = {"simple": 3, "moderate": 6, "complex": 12}
CORRIDOR = {"small": 1.0 / 12.0, "medium": 1.0 / 6.0, "large": 0.25}
#: (map grid side, evaluation tiles per side, exploration step budget) per (complexity, corridor), Table II
TABLE_II = {
    ("simple", "small"): (7, 3, 1500),
    ("simple", "medium"): (12, 6, 3000),
    ("simple", "large"): (18, 9, 4500),
    ("moderate", "small"): (12, 6, 3000),
    ("moderate", "medium"): (25, 12, 6000),
    ("moderate", "large"): (37, 18, 9000),
    ("complex", "small"): (25, 12, 6000),
    ("complex", "medium"): (50, 18, 12000),
    ("complex", "large"): (75, 24, 18000),
}
WALL_THICKNESS = 0.006


@dataclass(frozen=True)
class Maze:
    """Cells, open passages and walls of one maze, filling ``[0, size]^2`` (world units).

    Attributes
    ----------
    seed : int
        Seed it was generated with.
    complexity : str
        ``"simple"``, ``"moderate"`` or ``"complex"`` (3, 6, 12 cells per side).
    corridor : str
        ``"small"``, ``"medium"`` or ``"large"`` (the cell side, Table II of the DVBF-LM paper).
    n : int
        Cells per side.
    size : float
        Side of the square the maze fills.
    east : numpy.ndarray
        ``(n - 1, n)`` bool, True when a wall separates cell ``(i, j)`` from ``(i + 1, j)`` (``i``
        counts along x, ``j`` along y).
    north : numpy.ndarray
        ``(n, n - 1)`` bool, likewise toward ``(i, j + 1)``.
    walls : numpy.ndarray
        ``(K, 4)`` float axis-aligned boxes ``(cx, cy, sx, sy)``, including the outer boundary.
    """

    seed: int
    complexity: str
    corridor: str
    n: int
    size: float
    east: np.ndarray
    north: np.ndarray
    walls: np.ndarray

    @property
    def cell(self) -> float:
        """Side of one cell (``size / n``)."""
        return self.size / self.n

    @property
    def map_side(self) -> int:
        """Side of the latent map grid the paper uses for this maze (Table II)."""
        return TABLE_II[(self.complexity, self.corridor)][0]

    @property
    def tiles(self) -> int:
        """Evaluation tiles per side for the exploration ratio (Table II)."""
        return TABLE_II[(self.complexity, self.corridor)][1]

    @property
    def step_budget(self) -> int:
        """Exploration step budget the paper uses for this maze (Table II of the DVBF-LM paper)."""
        return TABLE_II[(self.complexity, self.corridor)][2]

    def cell_centre(self, i: int, j: int) -> np.ndarray:
        """Centre of cell ``(i, j)``.

        Parameters
        ----------
        i, j : int
            Cell indices along x and y.

        Returns
        -------
        numpy.ndarray
            ``(2,)`` float position.
        """
        return (np.array([i, j], float) + 0.5) * self.cell

    def cell_of(self, xy) -> tuple[int, int]:
        """Cell containing position ``xy`` (clipped to the maze).

        Parameters
        ----------
        xy : array_like
            Position; its first two entries are ``(x, y)``.

        Returns
        -------
        tuple of int
            ``(i, j)``.
        """
        ij = np.clip(np.floor(np.asarray(xy, float)[:2] / self.cell).astype(int), 0, self.n - 1)
        return int(ij[0]), int(ij[1])

    def neighbours(self, i: int, j: int) -> list[tuple[int, int]]:
        """Cells reachable from ``(i, j)`` in one step without crossing a wall.

        Parameters
        ----------
        i, j : int
            The cell, as for :meth:`cell_centre`.

        Returns
        -------
        list of tuple of int
        """
        out = []
        if i + 1 < self.n and not self.east[i, j]:
            out.append((i + 1, j))
        if i > 0 and not self.east[i - 1, j]:
            out.append((i - 1, j))
        if j + 1 < self.n and not self.north[i, j]:
            out.append((i, j + 1))
        if j > 0 and not self.north[i, j - 1]:
            out.append((i, j - 1))
        return out

    def segments(self) -> np.ndarray:
        """Wall centre lines.

        Returns
        -------
        numpy.ndarray
            ``(K, 4)`` float rows ``x0, y0, x1, y1``.
        """
        cx, cy, sx, sy = self.walls.T
        horiz = sx >= sy
        half = np.where(horiz, sx, sy) / 2
        return np.stack([np.where(horiz, cx - half, cx), np.where(horiz, cy, cy - half),
                         np.where(horiz, cx + half, cx), np.where(horiz, cy, cy + half)], 1)

    def occupancy(self, resolution: int = 200) -> np.ndarray:
        """Boolean raster of the walls (slightly dilated by half a pixel).

        Parameters
        ----------
        resolution : int, optional
            Pixels per side, default 200.

        Returns
        -------
        numpy.ndarray
            ``(resolution, resolution)`` bool, ``[ix, iy]`` True where a wall lies.
        """
        c = (np.arange(resolution) + 0.5) * self.size / resolution
        X, Y = np.meshgrid(c, c, indexing="ij")
        occ = np.zeros_like(X, bool)
        pad = self.size / resolution / 2
        for cx, cy, sx, sy in self.walls:
            occ |= (np.abs(X - cx) <= sx / 2 + pad) & (np.abs(Y - cy) <= sy / 2 + pad)
        return occ

    def tile_index(self, xy) -> np.ndarray:
        """Evaluation-tile index of positions (Table II tiles per side).

        Parameters
        ----------
        xy : array_like
            ``(K, >=2)`` or ``(>=2,)`` positions.

        Returns
        -------
        numpy.ndarray
            ``(K, 2)`` int tile indices, clipped to the grid.
        """
        xy = np.atleast_2d(np.asarray(xy, float))[:, :2]
        return np.clip(np.floor(xy / self.size * self.tiles).astype(int), 0, self.tiles - 1)


def exploration_ratio(maze: Maze, positions) -> float:
    """Fraction of the Table II evaluation tiles visited by ``positions`` (DVBF-LM paper, Appendix D).

    Parameters
    ----------
    maze : Maze
        The maze.
    positions : array_like
        ``(K, >=2)`` visited positions.

    Returns
    -------
    float
        In [0, 1].
    """
    idx = maze.tile_index(positions)
    return len({tuple(r) for r in idx}) / maze.tiles**2


def _carve(n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    east = np.ones((n - 1, n), bool)
    north = np.ones((n, n - 1), bool)
    seen = np.zeros((n, n), bool)
    stack = [(int(rng.integers(n)), int(rng.integers(n)))]
    seen[stack[0]] = True
    while stack:
        i, j = stack[-1]
        options = [(a, b) for a, b in ((i + 1, j), (i - 1, j), (i, j + 1), (i, j - 1))
                   if 0 <= a < n and 0 <= b < n and not seen[a, b]]
        if not options:
            stack.pop()
            continue
        a, b = options[int(rng.integers(len(options)))]
        if a != i:
            east[min(a, i), j] = False
        else:
            north[i, min(b, j)] = False
        seen[a, b] = True
        stack.append((a, b))
    return east, north


def _wall_boxes(n: int, cell: float, east: np.ndarray, north: np.ndarray, t: float) -> np.ndarray:
    size = n * cell
    boxes = [(size / 2, 0.0, size + t, t), (size / 2, size, size + t, t),
             (0.0, size / 2, t, size + t), (size, size / 2, t, size + t)]
    for i in range(n - 1):  # vertical walls at x = (i + 1) * cell, merged along y
        j = 0
        while j < n:
            if east[i, j]:
                k = j
                while k + 1 < n and east[i, k + 1]:
                    k += 1
                boxes.append(((i + 1) * cell, (j + k + 1) * cell / 2, t, (k - j + 1) * cell + t))
                j = k + 1
            else:
                j += 1
    for j in range(n - 1):  # horizontal walls at y = (j + 1) * cell, merged along x
        i = 0
        while i < n:
            if north[i, j]:
                k = i
                while k + 1 < n and north[k + 1, j]:
                    k += 1
                boxes.append(((i + k + 1) * cell / 2, (j + 1) * cell, (k - i + 1) * cell + t, t))
                i = k + 1
            else:
                i += 1
    return np.array(boxes, float)


def make_maze(seed: int, complexity: str = "moderate", corridor: str = "medium",
              open_fraction: float = 0.15) -> Maze:
    """A seeded random maze: a perfect maze (randomised depth-first search) with some inner walls removed.

    Parameters
    ----------
    seed : int
        Random seed.
    complexity : str, optional
        ``"simple"``, ``"moderate"`` (default) or ``"complex"``.
    corridor : str, optional
        ``"small"``, ``"medium"`` (default) or ``"large"``.
    open_fraction : float, optional
        Fraction in [0, 1] of the remaining inner walls removed (opens loops), default 0.15.

    Returns
    -------
    Maze

    Raises
    ------
    ValueError
        For an unknown complexity or corridor, or ``open_fraction`` outside [0, 1].
    """
    if complexity not in CELLS:
        raise ValueError(f"make_maze: complexity must be one of {sorted(CELLS)}, got {complexity!r}")
    if corridor not in CORRIDOR:
        raise ValueError(f"make_maze: corridor must be one of {sorted(CORRIDOR)}, got {corridor!r}")
    if not 0.0 <= open_fraction <= 1.0:
        raise ValueError(f"make_maze: open_fraction must lie in [0, 1], got {open_fraction}")
    n = CELLS[complexity]
    cell = CORRIDOR[corridor]
    rng = np.random.default_rng(seed)
    east, north = _carve(n, rng)
    for arr in (east, north):
        idx = np.flatnonzero(arr)
        k = int(round(open_fraction * len(idx)))
        if k:
            arr.flat[rng.choice(idx, size=k, replace=False)] = False
    t = WALL_THICKNESS * n * cell
    return Maze(seed=int(seed), complexity=complexity, corridor=corridor, n=n, size=n * cell,
                east=east, north=north, walls=_wall_boxes(n, cell, east, north, t))

"""Ground-truth occupancy grids rasterised from a layout.

A cell is occupied when its centre lies within half a cell of a shape (signed
distance <= resolution / 2), i.e. roughly every cell that the shape overlaps.
Free area is the count of unoccupied cells 4-connected to the start cell, times
the cell area; obstacles and walls do not count, and no robot inflation is applied.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from .geometry import Shape, shape_distance, shape_extent


@dataclass
class OccupancyGrid:
    """Boolean occupancy grid (rows = y, cols = x).

    Attributes
    ----------
    occupied : numpy.ndarray
        ``(rows, cols)`` bool, True where occupied.
    origin : tuple of float
        World ``(x, y)`` in metres of the corner of cell ``(0, 0)``.
    resolution : float
        Cell side in metres.
    """

    occupied: np.ndarray
    origin: tuple[float, float]
    resolution: float

    @property
    def shape(self) -> tuple[int, int]:
        """``(rows, cols)`` of the grid."""
        return self.occupied.shape

    def world_to_cell(self, xy) -> np.ndarray:
        """World points to integer cells.

        Parameters
        ----------
        xy : array_like
            ``(..., 2)`` float ``(x, y)`` in metres, world frame.

        Returns
        -------
        numpy.ndarray
            ``(..., 2)`` int ``(row, col)`` (not clipped; see :meth:`in_bounds`).
        """
        xy = np.asarray(xy, float)
        col = np.floor((xy[..., 0] - self.origin[0]) / self.resolution).astype(int)
        row = np.floor((xy[..., 1] - self.origin[1]) / self.resolution).astype(int)
        return np.stack([row, col], axis=-1)

    def cell_to_world(self, rc) -> np.ndarray:
        """Cells to the world coordinates of their centres.

        Parameters
        ----------
        rc : array_like
            ``(..., 2)`` ``(row, col)``.

        Returns
        -------
        numpy.ndarray
            ``(..., 2)`` float ``(x, y)`` in metres.
        """
        rc = np.asarray(rc, float)
        x = self.origin[0] + (rc[..., 1] + 0.5) * self.resolution
        y = self.origin[1] + (rc[..., 0] + 0.5) * self.resolution
        return np.stack([x, y], axis=-1)

    def in_bounds(self, rc) -> np.ndarray:
        """Whether cells lie inside the grid.

        Parameters
        ----------
        rc : array_like
            ``(..., 2)`` int ``(row, col)``.

        Returns
        -------
        numpy.ndarray
            ``(...)`` bool.
        """
        rc = np.asarray(rc)
        return ((rc[..., 0] >= 0) & (rc[..., 0] < self.shape[0])
                & (rc[..., 1] >= 0) & (rc[..., 1] < self.shape[1]))

    def reachable(self, start_xy) -> np.ndarray:
        """Mask of free cells 4-connected to the cell containing ``start_xy``.

        Parameters
        ----------
        start_xy : array_like
            ``(x, y)`` in metres.

        Returns
        -------
        numpy.ndarray
            ``(rows, cols)`` bool.

        Raises
        ------
        ValueError
            If the start lies in an occupied cell.
        """
        labels, _ = ndimage.label(~self.occupied)
        r, c = self.world_to_cell(start_xy)
        lab = labels[r, c]
        if lab == 0:
            raise ValueError(f"start {tuple(start_xy)} lies in an occupied cell")
        return labels == lab

    def free_area(self, start_xy) -> float:
        """Area of the free cells reachable from ``start_xy`` (no robot inflation).

        Parameters
        ----------
        start_xy : array_like
            As for :meth:`reachable`.

        Returns
        -------
        float
            Square metres.

        Raises
        ------
        ValueError
            If the start lies in an occupied cell.
        """
        return float(self.reachable(start_xy).sum() * self.resolution**2)

    def clearance(self) -> np.ndarray:
        """Distance from each cell centre to the nearest occupied cell (Euclidean distance transform).

        Returns
        -------
        numpy.ndarray
            ``(rows, cols)`` float metres (0 on occupied cells).
        """
        return ndimage.distance_transform_edt(~self.occupied) * self.resolution

    def inflated(self, radius: float) -> np.ndarray:
        """Occupied mask grown by ``radius`` (cells a disc robot's centre cannot enter).

        Parameters
        ----------
        radius : float
            Metres.

        Returns
        -------
        numpy.ndarray
            ``(rows, cols)`` bool.
        """
        return self.clearance() < radius

    def copy(self) -> OccupancyGrid:
        """A copy with its own ``occupied`` array.

        Returns
        -------
        OccupancyGrid
        """
        return OccupancyGrid(self.occupied.copy(), self.origin, self.resolution)


def rasterise(shapes, bounds, resolution: float = 0.05) -> OccupancyGrid:
    """Rasterise shapes into an occupancy grid.

    A cell is occupied when its centre lies within half a cell of a shape.

    Parameters
    ----------
    shapes : iterable of Box or Cylinder
        The shapes.
    bounds : tuple of float
        ``(xmin, ymin, xmax, ymax)`` in metres.
    resolution : float, optional
        Cell side in metres, default 0.05.

    Returns
    -------
    OccupancyGrid
    """
    xmin, ymin, xmax, ymax = bounds
    nx = int(np.ceil((xmax - xmin) / resolution - 1e-9))
    ny = int(np.ceil((ymax - ymin) / resolution - 1e-9))
    grid = OccupancyGrid(np.zeros((ny, nx), bool), (xmin, ymin), resolution)
    for s in shapes:
        paint(grid, s, True)
    return grid


def paint(grid: OccupancyGrid, shape: Shape, value: bool = True) -> None:
    """Set the cells covered by `shape` to `value` (in place)."""
    res = grid.resolution
    x0, y0, x1, y1 = shape_extent(shape)
    (r0, c0) = grid.world_to_cell([x0 - res, y0 - res])
    (r1, c1) = grid.world_to_cell([x1 + res, y1 + res])
    r0, c0 = max(r0, 0), max(c0, 0)
    r1, c1 = min(r1, grid.shape[0] - 1), min(c1, grid.shape[1] - 1)
    if r1 < r0 or c1 < c0:
        return
    rr, cc = np.mgrid[r0:r1 + 1, c0:c1 + 1]
    centres = grid.cell_to_world(np.stack([rr, cc], -1).reshape(-1, 2))
    inside = (shape_distance(shape, centres) <= res / 2).reshape(rr.shape)
    win = grid.occupied[r0:r1 + 1, c0:c1 + 1]
    win[inside] = value


def layout_grid(layout, resolution: float = 0.05) -> OccupancyGrid:
    """Ground-truth occupancy grid of a layout (its shapes rasterised over its bounds).

    Parameters
    ----------
    layout : Layout
        The layout.
    resolution : float, optional
        Cell side in metres, default 0.05.

    Returns
    -------
    OccupancyGrid
    """
    return rasterise(layout.shapes, layout.bounds, resolution)

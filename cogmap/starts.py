"""Start poses, one per seed, all different (the paper starts every trial somewhere else, section 4.1).

Seed ``k < n`` starts at the layout's own start pose ``k`` (``layout.starts``, chosen by hand).
Seed ``k >= n`` starts at a pose sampled from the free space with a generator seeded by ``k``:

* **free and clear**: the robot's centre lies at least ``robot radius + START_MARGIN_M`` from
  every occupied cell of the ground-truth grid;
* **reachable**: in the same connected part of that clear space as the layout's first start,
  so a disc robot can drive there and the free area measured from it is the same room;
* **distinct**: at least ``START_SEPARATION_M`` from the start of every lower seed.

The sample for seed ``k`` depends only on the layout and on the starts of seeds ``0..k-1``, so
each seed's start is fixed whatever other seeds a study runs.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

START_MARGIN_M = 0.3  # clearance beyond the robot radius
START_SEPARATION_M = 1.0  # minimum distance between the starts of two seeds
_MAX_TRIES = 2000


def clear_start_cells(grid, robot_radius: float, margin: float, anchor_xy) -> np.ndarray:
    """Cells where a disc robot of ``robot_radius`` has ``margin`` clearance and that are
    connected (8-neighbourhood) through such cells to ``anchor_xy``.

    Parameters
    ----------
    grid : OccupancyGrid
        Ground-truth occupancy grid (provides ``clearance()`` in metres and ``world_to_cell``).
    robot_radius : float
        Robot radius in metres.
    margin : float
        Extra clearance in metres beyond the radius.
    anchor_xy : sequence of float
        World ``(x, y)`` in metres of a point in the wanted connected part (the layout's first start).

    Returns
    -------
    numpy.ndarray of bool, shape (rows, cols)
        True for the clear cells in the anchor's connected component.

    Raises
    ------
    ValueError
        If the anchor itself does not have ``robot_radius + margin`` clearance.
    """
    clear = grid.clearance() >= robot_radius + margin
    labels, _ = ndimage.label(clear, structure=np.ones((3, 3)))
    r, c = grid.world_to_cell(anchor_xy)
    lab = labels[r, c]
    if lab == 0:
        raise ValueError(f"anchor {tuple(anchor_xy)} has less than {robot_radius + margin:.2f} m clearance")
    return labels == lab


def seed_start(layout, seed: int, robot_radius: float, grid=None, margin: float = START_MARGIN_M,
               separation: float = START_SEPARATION_M) -> tuple[float, float, float]:
    """The start pose (x, y, yaw) of ``seed`` in ``layout`` (see the module docstring).

    Parameters
    ----------
    layout : Layout
        The room; ``layout.starts`` are its hand-chosen start poses.
    seed : int
        Seed index, ``>= 0``.
    robot_radius : float
        Robot radius in metres.
    grid : OccupancyGrid, optional
        Ground-truth grid of ``layout``; built with ``layout_grid`` if omitted.
    margin : float
        Clearance in metres beyond the radius (default :data:`START_MARGIN_M`).
    separation : float
        Minimum distance in metres from the starts of lower seeds (default :data:`START_SEPARATION_M`).

    Returns
    -------
    tuple of float
        ``(x, y, yaw)``: position in metres, yaw in radians in [-pi, pi).

    Raises
    ------
    ValueError
        If ``seed < 0``, or no clear cell is ``separation`` away from the earlier starts after
        2000 draws.
    """
    if seed < 0:
        raise ValueError("seed must be >= 0")
    starts = [tuple(float(v) for v in s) for s in layout.starts]
    if seed < len(starts):
        return starts[seed]
    if grid is None:
        from cogmap.envs.occupancy import layout_grid

        grid = layout_grid(layout)
    cells = np.argwhere(clear_start_cells(grid, robot_radius, margin, starts[0][:2]))
    xy = grid.cell_to_world(cells)
    chosen = [np.asarray(s[:2]) for s in starts]
    for k in range(len(starts), seed + 1):
        rng = np.random.default_rng([k, 7919])
        for _ in range(_MAX_TRIES):
            j = int(rng.integers(len(xy)))
            p = xy[j]
            if min(float(np.hypot(*(p - q))) for q in chosen) >= separation:
                break
        else:
            raise ValueError(f"no start {separation} m away from the {len(chosen)} earlier starts in {layout.name}")
        yaw = float(rng.uniform(-np.pi, np.pi))
        chosen.append(p)
        if k == seed:
            return (float(p[0]), float(p[1]), yaw)
    raise AssertionError("unreachable")

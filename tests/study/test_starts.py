"""Every seed starts from its own pose: free, reachable, apart from the others."""

import numpy as np
import pytest

from cogmap.baselines.gridnav import inflate, shortest_paths
from cogmap.envs import make_layout
from cogmap.envs.occupancy import layout_grid
from cogmap.explore import default_config, make_sim
from cogmap.starts import START_MARGIN_M, START_SEPARATION_M, seed_start

RADIUS = 0.22


@pytest.mark.parametrize("name", ["mini_warehouse", "bedroom", "parking_lot"])
def test_five_seeds_start_at_five_free_reachable_distinct_poses(name):
    layout = make_layout(name)
    assert len(layout.starts) < 5  # some seeds need a sampled start
    grid = layout_grid(layout)
    poses = np.array([seed_start(layout, k, RADIUS, grid) for k in range(5)])
    assert np.allclose(poses[: len(layout.starts)], layout.starts)  # the hand-made starts first
    xy = poses[:, :2]
    gaps = np.hypot(*(xy[:, None] - xy[None]).transpose(2, 0, 1))
    assert np.all(gaps[np.triu_indices(5, 1)] >= START_SEPARATION_M)
    # free: the robot disc plus the margin clears every occupied cell
    cells = grid.world_to_cell(xy)
    assert np.all(grid.clearance()[cells[:, 0], cells[:, 1]] >= RADIUS + START_MARGIN_M - 1e-9)
    # reachable: a disc robot drives from the first start to each (shortest paths on the inflated grid)
    dist, _ = shortest_paths(inflate(grid.occupied, RADIUS / grid.resolution), tuple(cells[0]))
    assert np.all(np.isfinite(dist[cells[:, 0], cells[:, 1]]))
    # deterministic, and independent of the other seeds asked for
    assert seed_start(layout, 4, RADIUS) == tuple(poses[4])


def test_make_sim_starts_each_seed_at_its_own_pose():
    cfg = default_config("mini_warehouse")
    starts = []
    for seed in range(5):
        sim = make_sim("mini_warehouse", cfg, seed)
        try:
            starts.append(sim.true_pose())
        finally:
            sim.close()
    assert len({tuple(np.round(s, 6)) for s in starts}) == 5
    with pytest.raises(ValueError):
        seed_start(make_layout("mini_warehouse"), -1, RADIUS)

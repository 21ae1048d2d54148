"""Frontier goal choice on a hand-made map: the explore_lite cost and blacklisting."""

import numpy as np
import pytest

from cogmap.baselines import (
    FrontierConfig,
    FrontierExplorer,
    FrontierPaperConfig,
    FrontierPaperExplorer,
    OdomMap,
)

RES = 0.05


def _room(gaps) -> OdomMap:
    """A seen 6 m x 6 m room (centred on 0, 0) walled 0.2 m thick, with openings ``(x0, x1, y0, y1)``
    onto unknown space."""
    m = OdomMap((0.0, 0.0), 10.0, RES)
    n = m.seen.shape[0]
    rc = np.stack(np.meshgrid(np.arange(n), np.arange(n), indexing="ij"), -1)
    xy = m.to_xy(rc.reshape(-1, 2)).reshape(n, n, 2)
    x, y = xy[..., 0], xy[..., 1]
    inside = (np.abs(x) < 3) & (np.abs(y) < 3)
    wall = inside & ((np.abs(x) > 2.8) | (np.abs(y) > 2.8))
    for x0, x1, y0, y1 in gaps:
        wall &= ~((x > x0) & (x < x1) & (y > y0) & (y < y1))
    m.seen[:] = inside
    m.occ[:] = wall
    m.bbox = (0, n, 0, n)
    return m


# a 1 m opening in the east wall and a 3 m opening in the north wall; frontier cells are the
# outermost seen cells of each opening (x = 2.975 or y = 2.975), minus the one cell at each end
# that touches the wall: 18 and 58 cells
EAST, NORTH = (2.7, 3.1, -0.5, 0.5), (-1.5, 1.5, 2.7, 3.1)
ROBOT = np.array([0.525, 0.325, 0.0])  # a cell centre


def _explorer(cls, cfg):
    pol = cls(cfg)
    pol.map = _room([EAST, NORTH])
    return pol


def test_explore_lite_cost_orders_the_frontiers():
    pol = _explorer(FrontierExplorer, FrontierConfig())
    frontiers = sorted(pol.detect(ROBOT), key=lambda f: f.centroid[0], reverse=True)  # east first
    assert len(frontiers) == 2
    east, north = frontiers
    # hand-derived: the robot's y lies inside the east opening and its x inside the north one
    assert east.size_m == pytest.approx(18 * RES) and north.size_m == pytest.approx(58 * RES)
    assert east.min_distance == pytest.approx(2.45) and north.min_distance == pytest.approx(2.65)
    assert east.cost == pytest.approx(3 * 2.45 - 0.9) and north.cost == pytest.approx(3 * 2.65 - 2.9)
    assert np.allclose(east.centroid, [2.975, 0.0]) and np.allclose(north.centroid, [0.0, 2.975])
    # the larger, farther opening wins with explore_lite's scales (3, 1) ...
    for cls, cfg in ((FrontierExplorer, FrontierConfig()), (FrontierPaperExplorer, FrontierPaperConfig())):
        pol = _explorer(cls, cfg)
        pol.decide(ROBOT)
        assert pol.goal[1] > 2.5, cls.__name__
    # ... the nearer one when distance weighs more (cost 20 * 2.45 - 0.9 < 20 * 2.65 - 2.9)
    pol = _explorer(FrontierPaperExplorer, FrontierPaperConfig(potential_scale=20.0))
    pol.decide(ROBOT)
    assert pol.goal[0] > 2.5


def test_paper_variant_sends_the_centroid_the_other_the_nearest_reachable_cell():
    paper = _explorer(FrontierPaperExplorer, FrontierPaperConfig())
    paper.decide(ROBOT)
    assert np.allclose(paper.goal, [0.0, 2.975])  # explore_lite's goal: the centroid itself
    ours = _explorer(FrontierExplorer, FrontierConfig())
    ours.decide(ROBOT)
    blocked = ours._plan[1]
    g = (ours.map.to_cell(ours.goal) - np.array(ours._plan[2])) // ours.cfg.plan_factor
    assert not blocked[g[0], g[1]] and np.isfinite(ours._plan[3][g[0], g[1]])  # a reachable planning cell


def test_a_goal_that_fails_n_times_is_never_chosen_again():
    cfg = FrontierPaperConfig()
    pol = _explorer(FrontierPaperExplorer, cfg)
    pol.decide(ROBOT)
    first = pol.goal.copy()
    assert first[1] > 2.5
    # failures need not be consecutive: a successful move in between does not forgive them
    outcomes = [False, True, False, True, False]
    for moved in outcomes:
        pol.observe(ROBOT, None, None, moved)
        pol.decide(ROBOT)
    assert pol.track.failures < cfg.max_failures and pol.blacklisted == 1
    assert any(np.hypot(*(b - first)) < 1e-9 for b in pol.blacklist)
    chosen = [pol.goal.copy()]
    for _ in range(30):
        pol.observe(ROBOT, None, None, True)
        if pol.decide(ROBOT) is None:
            break
        chosen.append(pol.goal.copy())
    assert chosen[0][0] > 2.5  # the east opening next
    assert all(np.hypot(*(g - first)) > cfg.blacklist_radius for g in chosen)
    # the robot never gets closer to the east frontier either: it is blacklisted after the timeout
    assert pol.done and pol.blacklisted == 2


def test_nearest_cell_variant_forgives_failures_after_a_successful_move():
    cfg = FrontierConfig()
    pol = _explorer(FrontierExplorer, cfg)
    pol.decide(ROBOT)
    first = pol.goal.copy()
    for moved in [False, True, False, True, False]:
        pol.observe(ROBOT, None, None, moved)
        pol.decide(ROBOT)
    assert pol.blacklisted == 0 and np.hypot(*(pol.goal - first)) < cfg.blacklist_radius

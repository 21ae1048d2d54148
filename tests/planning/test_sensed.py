"""The sensed grid (planning/sensed.py) and the exploration terms that read it, against
hand-made cases with closed-form or brute-force answers."""

from __future__ import annotations

import numpy as np
import pytest
from planning_builders import chain, graph_model

from cogmap.planning import efe
from cogmap.planning import sensed as sg
from cogmap.planning.arrays import prepare
from cogmap.planning.context import DenseStep, LocalStep
from cogmap.planning.decide import decide


def _room(size=4.0, res=0.1, pad=5):
    """A square room [0, size]^2 fully sensed: inside free, a one-cell wall just outside it
    occupied, beyond that unknown (``pad`` cells of margin)."""
    n = int(round(size / res))
    cells = np.zeros((n + 2 * pad, n + 2 * pad), dtype=np.int8)
    cells[pad - 1:pad + n + 1, pad - 1:pad + n + 1] = sg.OCCUPIED
    cells[pad:pad + n, pad:pad + n] = sg.FREE
    return sg.SensedGrid(cells, np.array([-pad * res, -pad * res]), res)


def test_empty_grid_and_bad_input():
    g = sg.empty((1.0, 2.0), 0.5, 2.0)
    assert g.cells.shape == (8, 8) and (g.cells == sg.UNKNOWN).all()
    np.testing.assert_allclose(g.origin, [-1.0, 0.0])
    with pytest.raises(ValueError):
        sg.empty((0, 0), 0.0)


def test_mark_scan_frees_rays_and_occupies_returns():
    g = sg.empty((0.0, 0.0), 0.1, 3.0)
    g = sg.mark_scan(g, (0.0, 0.0), np.array([[2.0, 0.0], [0.0, -1.5]]))
    rc = sg.to_cells(g, np.array([[2.05, 0.05], [0.05, -1.45]]))
    assert (g.cells[rc[:, 0], rc[:, 1]] == sg.OCCUPIED).all()
    on_ray = sg.to_cells(g, np.stack([np.arange(0.05, 1.9, 0.1), np.full(19, 0.05)], axis=1))
    assert (g.cells[on_ray[:, 0], on_ray[:, 1]] == sg.FREE).all()
    off = sg.to_cells(g, np.array([[1.05, 1.05], [-1.05, 0.05]]))
    assert (g.cells[off[:, 0], off[:, 1]] == sg.UNKNOWN).all()
    # an occupied cell stays occupied when a later ray crosses it
    g2 = sg.mark_scan(g, (0.0, 0.0), np.array([[2.9, 0.0]]))
    assert g2.cells[rc[0, 0], rc[0, 1]] == sg.OCCUPIED


def test_grid_grows_to_hold_far_returns_without_moving_cells():
    g = sg.mark_scan(sg.empty((0.0, 0.0), 0.2, 2.0), (0.0, 0.0), np.array([[1.0, 0.0]]))
    before = sg.to_cells(g, np.array([[1.05, 0.05]]))[0]
    assert g.cells[before[0], before[1]] == sg.OCCUPIED
    big = sg.mark_scan(g, (0.0, 0.0), np.array([[9.0, -7.0]]))
    assert big.cells.shape[0] > g.cells.shape[0] and big.cells.shape[1] > g.cells.shape[1]
    after = sg.to_cells(big, np.array([[1.05, 0.05], [9.05, -6.95]]))
    assert (big.cells[after[:, 0], after[:, 1]] == sg.OCCUPIED).all()


def test_unseen_area_of_an_unknown_plane_is_the_disc_and_zero_in_a_sensed_room():
    radius, rays, res = 3.0, 64, 0.1
    g = sg.empty((0.0, 0.0), res, 10.0)
    full = sg.view_area(radius, rays, res, skip=0.0)
    # the wedges of the fan add up to the disc (closed form pi r^2, up to the half-step ends)
    assert abs(full - np.pi * radius**2) / (np.pi * radius**2) < 0.05
    np.testing.assert_allclose(sg.unseen_area(g, [[0.0, 0.0], [1.0, 1.0]], radius, rays, skip=0.0), full)
    room = _room()
    assert sg.unseen_area(room, [[2.0, 2.0]], radius, rays)[0] == 0.0


def test_unseen_area_behind_an_opening_is_the_wedge_through_it():
    # a sensed room whose east wall has a doorway; beyond it nothing is known
    room = _room(4.0, 0.1)
    door = sg.to_cells(room, np.array([[4.05, 1.55], [4.05, 2.45]]))
    room.cells[door[0, 0]:door[1, 0] + 1, door[0, 1]] = sg.FREE  # a 1 m doorway in the east wall
    far = sg.unseen_area(room, [[3.5, 2.0]], 5.0, 180)[0]  # next to the doorway: wide wedge
    across = sg.unseen_area(room, [[0.5, 2.0]], 5.0, 180)[0]  # across the room: narrow wedge
    out_of_range = sg.unseen_area(room, [[0.5, 2.0]], 3.0, 180)[0]  # the doorway is 3.5 m away
    assert far > across > 0.0 and out_of_range == 0.0
    # closed form: beyond the door, the wedge between the rays through the (grown) jambs.
    # From (0.5, 2): half-angle atan(0.4 / 3.5) over radii 3.6 .. 5 m
    half = np.arctan2(0.4, 3.5)
    wedge = half * (5.0**2 - 3.6**2)
    assert abs(across - wedge) / wedge < 0.2
    # from (3.5, 2) the opening subtends a wide angle: far more than the narrow wedge, at most half the annulus
    assert 3 * across < far < 0.5 * np.pi * (5.0**2 - 0.5**2)


def test_view_weights_lie_beyond_the_doorway_and_add_up_to_the_unseen_area():
    room = _room(4.0, 0.1)
    door = sg.to_cells(room, np.array([[4.05, 1.55], [4.05, 2.45]]))
    room.cells[door[0, 0]:door[1, 0] + 1, door[0, 1]] = sg.FREE
    xy = np.array([[0.5, 2.0], [3.5, 2.0]])
    for free_path in (np.inf, 2.0):
        points, weights = sg.view_weights(room, xy, 5.0, 180, free_path=free_path)
        assert points.shape[:3] == weights.shape and points.shape[0] == 2 and points.shape[-1] == 2
        np.testing.assert_allclose(weights.sum(axis=(1, 2)), sg.unseen_area(room, xy, 5.0, 180, free_path=free_path))
        w = weights > 0
        # every sample that counts lies east of the wall, in the band the doorway (grown by one
        # cell) lets through, widening with distance from the viewpoint
        assert (points[..., 0][w] > 4.0).all()
        ys = points[0, ..., 1][w[0]]
        assert 1.0 < ys.min() and ys.max() < 3.0
    # with a finite free path, a sample behind more unknown counts less (exp(-u / free_path))
    _, fin = sg.view_weights(room, xy[1:], 5.0, 180, free_path=2.0)
    _, inf = sg.view_weights(room, xy[1:], 5.0, 180)
    ratio = fin[inf > 0] / inf[inf > 0]
    assert ((ratio > 0) & (ratio < 1)).all()


def test_a_known_outline_cuts_the_imagined_view_as_the_closed_form():
    radius, rays, res = 3.0, 180, 0.1
    g = sg.empty((0.0, 0.0), res, 10.0)
    xy = [[0.0, 0.0]]
    full = sg.unseen_area(g, xy, radius, rays, skip=0.0)[0]
    # an outline far from the view changes nothing; one 1 m east of the viewpoint keeps the part
    # of the disc west of x = 1: pi r^2 / 2 + the strip 0 <= x <= 1 (closed form)
    assert sg.unseen_area(g, xy, radius, rays, skip=0.0, bounds=(-5, -5, 5, 5))[0] == full
    cut = sg.unseen_area(g, xy, radius, rays, skip=0.0, bounds=(-5.0, -5.0, 1.0, 5.0))[0]
    strip = np.sqrt(radius**2 - 1.0) + radius**2 * np.arcsin(1.0 / radius)  # int_0^1 2 sqrt(r^2 - x^2) dx
    assert cut == pytest.approx(np.pi * radius**2 / 2 + strip, rel=0.03)
    points, weights = sg.view_weights(g, xy, radius, rays, skip=0.0, bounds=(-5.0, -5.0, 1.0, 5.0))
    assert (points[..., 0][weights > 0] <= 1.0).all() and weights.sum() == pytest.approx(cut)
    for bad in [(0, 0, 0, 1), (0, 0, 1), (0, 0, 1, np.nan), "box", None]:
        with pytest.raises(ValueError, match="xmin < xmax"):
            sg.check_bounds(bad, "test")
    assert sg.check_bounds([0, 1, 2, 3], "test") == (0.0, 1.0, 2.0, 3.0)


def test_frontier_points_lie_on_the_edge_of_the_known():
    g = sg.empty((0.0, 0.0), 0.1, 3.0)
    g = sg.mark_scan(g, (0.0, 0.0), np.array([[2.0, 0.0]]))
    pts = sg.frontier_points(g, 0.5)
    assert pts.shape[0] > 0
    rc = sg.to_cells(g, pts)
    assert (g.cells[rc[:, 0], rc[:, 1]] == sg.FREE).all()
    assert np.all(np.abs(pts[:, 1]) < 0.2)  # the only free cells are along the ray
    assert sg.frontier_points(_room(), 0.5).shape == (0, 2)  # a closed, sensed room has none


def test_line_of_sight_and_crossed_segments():
    room = _room(4.0, 0.1)
    room.cells[:, sg.to_cells(room, np.array([[2.0, 0.0]]))[0, 1]] = sg.OCCUPIED  # a wall at x = 2
    los = sg.line_of_sight(room, [[1.0, 1.0]], [[1.5, 3.0], [3.0, 1.0]])
    assert los.tolist() == [[True, False]]
    hit = sg.crossed_segments(np.array([[1.0, 0.02]]), [[0, 0], [0, 0], [0, 0]], [[2, 0], [0, 2], [1.05, 0]])
    assert hit.tolist() == [True, False, False]  # the last one ends at the point (not tested)


def test_geodesic_labels_go_around_walls():
    room = _room(4.0, 0.1)
    wall = sg.to_cells(room, np.array([[2.0, 0.0], [2.0, 3.0]]))
    room.cells[wall[0, 0]:wall[1, 0], wall[0, 1]] = sg.OCCUPIED  # wall at x = 2 from y = 0 to 3
    label, dist = sg.geodesic_labels(room, [[1.0, 1.0]], 20.0)
    a, b = sg.lookup(room, dist, [[1.0, 2.0], [3.0, 1.0]], np.inf)
    assert abs(a - 1.0) < 0.11  # straight up: 1 m
    # around the wall's end (x 1.9-2.2 and up to y 3.1 once grown by one cell): the shortest way
    # passes its two corners; the 8-connected path is at most 8 % longer
    shortest = np.hypot(0.85, 2.15) + 0.4 + np.hypot(0.75, 2.15)
    assert shortest - 0.2 <= b <= 1.09 * shortest
    c = sg.lookup(room, dist, [[1.5, 3.5]], np.inf)[0]  # diagonal, in the open: not |dx| + |dy| = 3
    assert c <= 1.09 * np.hypot(0.5, 2.5) < 3.0
    assert sg.lookup(room, label, [[3.0, 1.0]], -1)[0] == 0
    assert np.isinf(sg.geodesic_labels(room, [[1.0, 1.0]], 1.0)[1][sg.to_cells(room, [3.0, 1.0])[0],
                                                                     sg.to_cells(room, [3.0, 1.0])[1]])


def test_rank_viewpoints_is_most_information_per_metre_and_keeps_near_ties():
    gain = np.array([10.0, 30.0, 5.0, 50.0, 0.0])
    path = np.array([1.0, 4.0, 0.0, np.inf, 0.5])
    # scores 10/2 = 5, 30/5 = 6, 5/1 = 5; no path or no gain: left out; ties keep their order
    assert sg.rank_viewpoints(gain, path).tolist() == [1, 0, 2]
    assert sg.rank_viewpoints(gain, path, keep=0, keep_ratio=0.8).tolist() == [0, 1, 2]  # 5 >= 0.8 * 6
    assert sg.rank_viewpoints(gain, path, keep=0, keep_ratio=0.9).tolist() == [1, 0, 2]
    assert sg.rank_viewpoints(gain, path, keep=3, keep_ratio=0.0).tolist() == [1, 0, 2]  # no path: not kept
    assert sg.rank_viewpoints(gain, np.full(5, np.inf)).size == 0
    assert sg.rank_viewpoints(gain, path, detour=10.0).tolist() == [1, 0, 2]  # 30/14 > 10/11 > 5/10


def test_state_toward_prefers_the_nearest_state_and_breaks_near_ties_by_believed_steps():
    way = np.array([3.0, 1.0, 1.05, 0.5])
    steps = np.array([0.0, 2.0, 1.0, np.inf])  # the nearest one has no believed path
    assert sg.state_toward(way, steps, 1.0, 0.1) == 2  # 1.05 + 0.1 < 1.0 + 0.2
    assert sg.state_toward(way, steps, 1.0, 0.0) == 1
    assert sg.state_toward(way, steps, 2.0, 2.0) == 0  # a heavy path weight keeps the robot where it is
    assert sg.state_toward(np.full(2, np.inf), np.zeros(2)) == -1


def test_mark_sweep_fills_the_scan_polygon_like_the_coverage_count():
    from cogmap.metrics import scan_mask

    a = np.arange(360) * 2 * np.pi / 360 + 0.3
    r = np.clip(3.0 + 2.0 * np.sin(3 * a), 0.3, 12.0)  # a star-shaped room, 1-5 m
    robot = np.array([0.4, -0.7])
    ends = robot + r[:, None] * np.stack([np.cos(a), np.sin(a)], axis=1)
    g = sg.mark_sweep(sg.empty(robot, 0.1), robot, ends, ends[::7])
    # the filled polygon of the same end points (cv2.fillPoly, the studies' coverage rule) is the
    # reference; they differ only on the boundary ring (fillPoly's vertices sit on cell corners)
    ref = scan_mask(g.cells.shape, g.origin + g.resolution / 2, g.resolution, ends)
    ours = g.cells != sg.UNKNOWN
    assert (ours != ref).sum() <= 0.05 * ref.sum()
    hit = sg.to_cells(g, ends[::7])
    assert (g.cells[hit[:, 0], hit[:, 1]] == sg.OCCUPIED).all()
    # beams that return nothing (ending at the range) still sweep free space, with no gaps
    # between them far away; drawn from the returns alone (mark_scan) the open plane stays unknown
    far = robot + 11.0 * np.stack([np.cos(a[::4]), np.sin(a[::4])], axis=1)  # 90 beams
    open_plane = sg.mark_sweep(sg.empty(robot, 0.2), robot, far)
    disc = np.hypot(*(sg.to_cells(open_plane, robot)[:, None, None] - np.indices(open_plane.cells.shape))) * 0.2
    assert (open_plane.cells[disc < 10.5] == sg.FREE).all() and not (open_plane.cells == sg.OCCUPIED).any()
    assert (sg.mark_scan(sg.empty(robot, 0.2), robot, np.zeros((0, 2))).cells == sg.FREE).sum() == 1
    # an occupied cell stays occupied; unknown input of too few beams marks only the robot's cell
    again = sg.mark_sweep(g, robot, ends)
    assert (again.cells[hit[:, 0], hit[:, 1]] == sg.OCCUPIED).all()
    two = sg.mark_sweep(sg.empty(robot, 0.1), robot, ends[:2])
    assert (two.cells == sg.FREE).sum() == 1


def test_unseen_area_through_unknown_space_decays_as_the_closed_form():
    # an unknown plane, no walls: sum of exp(-u / L) dA over the disc of radius R, u = distance,
    # = 2 pi L^2 (1 - exp(-R / L) (1 + R / L)); the samples stand for annular wedges of 0.05 m
    L, R, res = 4.0, 12.0, 0.05
    g = sg.empty((0.0, 0.0), res, 14.0)
    closed = 2 * np.pi * L**2 * (1 - np.exp(-R / L) * (1 + R / L))
    got = sg.unseen_area(g, [[0.0, 0.0]], R, 360, skip=0.0, free_path=L)[0]
    assert abs(got - closed) <= 0.01 * closed
    assert abs(sg.view_area(R, 360, res, skip=0.0, free_path=L) - got) <= 1e-9 * got
    # with no free path limit it is the disc; a known free ring in front costs nothing
    assert abs(sg.unseen_area(g, [[0.0, 0.0]], R, 360, skip=0.0)[0] - np.pi * R**2) <= 0.01 * np.pi * R**2
    ring = g.cells.copy()
    near = np.hypot(*(np.indices(ring.shape) - sg.to_cells(g, [0.0, 0.0])[:, None, None])) * res < 2.0
    ring[near] = sg.FREE
    seen_ring = sg.SensedGrid(ring, g.origin, res)
    beyond = sg.unseen_area(seen_ring, [[0.0, 0.0]], R, 360, skip=0.0, free_path=L)[0]
    a = 2.0  # unknown from 2 m on: 2 pi int_a^R r exp(-(r - a) / L) dr
    shell = 2 * np.pi * (L * a + L**2 - np.exp(-(R - a) / L) * (L * R + L**2))
    assert abs(beyond - shell) <= 0.02 * shell


def test_path_lengths_go_around_walls_and_lookup_near_reads_beside_a_wall():
    room = _room(4.0, 0.1)
    wall = sg.to_cells(room, np.array([[2.0, 0.0], [2.0, 3.0]]))
    room.cells[wall[0, 0]:wall[1, 0], wall[0, 1]] = sg.OCCUPIED  # wall at x = 2 from y = 0 to 3
    dist = sg.path_lengths(room, [1.0, 1.0])
    np.testing.assert_array_equal(dist, sg.geodesic_labels(room, [[1.0, 1.0]], 1e3)[1])
    on_wall = np.array([[2.05, 1.0]])  # a point on the wall: not passable itself
    assert np.isinf(sg.lookup(room, dist, on_wall, np.inf)[0])
    near = sg.lookup_near(room, dist, on_wall, cells=2)[0]
    assert 0.8 <= near <= 1.0  # the passable cell nearest to it on the robot's side
    assert np.isinf(sg.lookup_near(room, dist, [[50.0, 50.0]])[0])  # outside the grid


# -- the EFE term ----------------------------------------------------------------------------
def _arrays(view):
    G, poses = chain(6)
    return graph_model(G, poses, visited=np.arange(6) < 3, num_obs=4, view=np.asarray(view, float))


def test_sensed_info_gain_is_info_gain_times_the_expected_unseen_fraction():
    view = np.array([0.0, 0.1, 0.2, 0.9, 0.5, 1.0])
    arrays = _arrays(view)
    acts = np.array([0, 6, 12])  # east, west, stay
    for local in (True, False):
        prep = prepare(arrays, local=local)
        q0 = np.zeros(6)
        q0[2] = 1.0
        ctx = (LocalStep(prep, (2,), (1.0,), acts) if local
               else DenseStep(prep, [np.tile(q0, (3, 1))], acts[:, None]))
        # brute force: predicted state distribution from the dense transitions, then the product
        B = arrays.live_B(0)
        qs = np.stack([B[:, :, a] @ q0 for a in acts])
        expected = (efe.state_info_gain(ctx) + efe.param_info_gain(ctx)) * (qs @ view)
        np.testing.assert_allclose(efe.sensed_info_gain(ctx), expected, atol=1e-12)
    plain = prepare(_arrays(np.ones(6)), local=True)
    ctx1 = LocalStep(plain, (2,), (1.0,), acts)
    np.testing.assert_allclose(efe.sensed_info_gain(ctx1), efe.state_info_gain(ctx1) + efe.param_info_gain(ctx1))


def test_sensed_exploration_is_composable_and_signed_like_the_other_terms():
    obj = efe.sensed_exploration(inductive_weight=2.0)
    assert obj.names == ("sensed_info_gain", "inductive", "collision")
    assert efe.objective({"sensed_info_gain": 1.0}).uses(efe.sensed_info_gain)
    arrays = _arrays([0.0, 0.0, 0.0, 1.0, 1.0, 1.0])
    ctx = LocalStep(prepare(arrays, local=True), (2,), (1.0,), np.array([0, 6]))
    g = efe.objective([(efe.sensed_info_gain, 1.0)])(ctx)
    # G = -value: the move toward the unseen side (east, to state 3) has the lower EFE
    assert g[0] < g[1]
    np.testing.assert_allclose(g, -efe.sensed_info_gain(ctx))


def test_mcts_follows_the_inductive_pull_to_a_far_informative_state():
    G, poses = chain(16)
    visited = np.ones(16, dtype=bool)
    visited[15] = False
    view = np.full(16, 0.05)
    view[15] = 1.0
    arrays = graph_model(G, poses, visited=visited, num_obs=4, view=view, inductive_depth=30)
    q = np.zeros(16)
    q[5] = 1.0
    from cogmap.planning.mcts import MCTSConfig

    cfg = MCTSConfig(depth=3, simulations=30)
    toward = decide(arrays, q, None, efe.sensed_exploration(), goal_states=np.array([15]), config=cfg, rng=0)
    assert toward.action == 0  # east, toward state 15, ten steps beyond the depth-3 horizon
    back = decide(arrays, q, None, efe.sensed_exploration(), goal_states=np.array([0]), config=cfg, rng=0)
    assert back.action == 6

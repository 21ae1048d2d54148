"""Next-best view on the robot's own map: its gain is the unseen area a scan would sweep (checked
against the disc and the cut disc in closed form), and it explores a room by itself."""

import numpy as np
import pytest

from cogmap.baselines.nbv import NBVConfig, NextBestView, unseen_gains


def _blank(size_m=30.0, res=0.1):
    n = int(round(size_m / res))
    return np.zeros((n, n), bool), np.zeros((n, n), bool), n


def test_gain_of_an_unseen_open_plane_is_the_disc():
    seen, occ, n = _blank()
    g = unseen_gains(seen, occ, 0.1, [[n // 2, n // 2]], rays=180, max_range=12.0)[0]
    assert g == pytest.approx(np.pi * 12.0**2, rel=0.01)
    # behind unseen space a sample counts exp(-r / lam): 2 pi lam^2 (1 - e^(-R/lam) (1 + R/lam))
    lam, R = 4.0, 12.0
    g = unseen_gains(seen, occ, 0.1, [[n // 2, n // 2]], rays=180, max_range=R, free_path=lam)[0]
    assert g == pytest.approx(2 * np.pi * lam**2 * (1 - np.exp(-R / lam) * (1 + R / lam)), rel=0.02)


def _strip(R, a, b):
    """Area of the disc of radius R between the vertical lines x = a and x = b (closed form)."""
    F = lambda x: x * np.sqrt(R**2 - x**2) + R**2 * np.arcsin(x / R)  # noqa: E731
    return F(b) - F(a)


def test_a_wall_cuts_the_disc_and_seen_cells_do_not_count():
    seen, occ, n = _blank()
    c0 = n // 2
    occ[:, c0 + 30] = True  # a wall of cells 2.95-3.05 m east of the viewpoint (a cell centre)
    R = 12.0
    g = unseen_gains(seen, occ, 0.1, [[c0, c0]], rays=360, max_range=R)[0]
    assert g == pytest.approx(_strip(R, -R, 2.95), rel=0.01)
    seen[:, : c0 + 1] = True  # swept: every cell up to the viewpoint's own column (x < 0.05 m)
    half = unseen_gains(seen, occ, 0.1, [[c0, c0]], rays=360, max_range=R)[0]
    assert half == pytest.approx(_strip(R, 0.05, 2.95), rel=0.02)


def _target_after_an_open_scan(bounds):
    """The viewpoint chosen after one scan of an open plane from the origin (every beam at range)."""
    pol = NextBestView(NBVConfig(bounds=bounds))
    angles = np.linspace(-np.pi, np.pi, 360, endpoint=False)
    pose = np.zeros(3)
    pol.observe(pose, np.full(angles.size, 12.0), angles, None)
    pol.decide(pose)
    return pol.target


def test_a_known_outline_is_wall_to_its_rays():
    free = _target_after_an_open_scan(None)
    assert np.array_equal(_target_after_an_open_scan((-40, -40, 40, 40)), free)  # beyond every ray: no change
    assert free[0] > 2.0  # the open plane: east, by the lattice's tie-break
    # nothing lies east of x = 1 (or north of y = 1): the view worth the detour lies the other way
    assert _target_after_an_open_scan((-40, -40, 1, 40))[0] < -2.0
    assert _target_after_an_open_scan((-40, -40, 40, 1))[1] < -2.0
    with pytest.raises(ValueError, match="NBVConfig.bounds"):
        NBVConfig(bounds=(1, 0, 0, 1))


def test_it_explores_the_mini_warehouse_by_itself():
    pytest.importorskip("pybullet", reason="needs the sim extra")
    from cogmap.baselines import coverage_tracker, run_policy
    from cogmap.explore import default_config, make_sim

    cfg = default_config("mini_warehouse")
    sim = make_sim("mini_warehouse", cfg, 0)
    try:
        pol = NextBestView(NBVConfig(step_length=cfg.influence_radius, robot_radius=sim.config.robot_radius,
                                     lidar_range=sim.config.lidar_range))
        ep = run_policy(sim, pol, 60)
        assert ep.rows[-1]["mode"] == "done"  # it declared itself finished before the budget
        assert len(ep.rows) < 60
        assert coverage_tracker(sim).coverage >= 0.95
    finally:
        sim.close()

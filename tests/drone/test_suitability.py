"""Suitability and the observation pipeline against DRONE.md 2.2-2.3."""

import numpy as np
import pytest

from cogmap.genmodel.suitability import (
    clearance,
    density,
    segments_clear,
    suitability,
    voxelise,
    waypoint_suitability,
)

# DRONE.md 2.3 reference table (recomputed from the e98ed45 formula)
TABLE = [(10, 0, 0.9527), (4, 0, 0.9407), (3.5, 0, 0.8732), (3, 0, 0.6194), (2, 0, 0.2980),
         (1, 0, 0.2862), (10, 0.15, 0.8333), (10, 0.5, 0.6706)]


@pytest.mark.parametrize(("d", "rho", "s"), TABLE)
def test_reference_table(d, rho, s):
    assert suitability(d, rho) == pytest.approx(s, abs=1e-4)


def test_vectorised_matches_scalar_and_threshold_clearance():
    d = np.array([r[0] for r in TABLE], float)
    rho = np.array([r[1] for r in TABLE], float)
    np.testing.assert_allclose(suitability(d, rho), [r[2] for r in TABLE], atol=1e-4)
    # the 0.75 threshold sits at about 3.21 m clearance in open space
    assert suitability(3.20, 0) < 0.75 < suitability(3.22, 0)


def test_overrides_and_normalisation_by_hand():
    sig = 1 / (1 + np.exp(-4 * (1.0 - 3)))
    dens = 1 / (1 + np.exp(12 * (0.0 - 0.15)))
    assert suitability(1.0, 0.0) == pytest.approx((0.8 * sig * (1 / 1.2) ** 2 + 0.4 * dens) / 1.2, abs=1e-12)
    dens_hi = 1 / (1 + np.exp(12 * (0.9 - 0.15))) * max(0.2, 1 - 2 * 0.5)
    safe = 1 / (1 + np.exp(-4 * 7.0))
    assert suitability(10.0, 0.9) == pytest.approx((0.8 * safe + 0.4 * dens_hi) / 1.2, abs=1e-12)
    assert 0.0 <= suitability(0.0, 5.0) <= suitability(20.0, 0.0) <= 1.0


def test_voxelise_clearance_density():
    pts = np.array([[0.01, 0.01, 0.01], [0.02, 0.03, 0.04], [1.0, 0.0, 0.0], [4.0, 0, 0], [6.0, 0, 0]])
    v = voxelise(pts)
    assert len(v) == 4  # the first two share a 0.15 m voxel
    np.testing.assert_allclose(v[np.argmin(np.linalg.norm(v, axis=1))], [0.015, 0.02, 0.025])
    assert len(voxelise(pts, min_points=2)) == 1
    assert clearance([0, 0, 0], v) == pytest.approx(np.linalg.norm([0.015, 0.02, 0.025]))
    assert clearance([0, 0, 0], np.zeros((0, 3))) == 10.0
    assert density([0, 0, 0], v) == pytest.approx(3 / (4 / 3 * np.pi * 125))
    with pytest.raises(ValueError, match="voxel size"):
        voxelise(pts, voxel=0)


def test_segments_clear():
    v = np.array([[5.0, 1.0, 0.0]])
    ok = segments_clear(np.array([[0.0, 0, 0], [0.0, 10, 0]]), [10.0, 0, 0], v, margin=1.5)
    assert list(ok) == [False, True]


def test_waypoint_suitability_current_clearance_caps_every_candidate():
    # DRONE.md 2.3 quirk: the current d_obs caps every candidate
    W = np.array([[0.0, 50, 5], [0.0, -50, 5]])
    far_target = [500.0, 0, 5]
    S = waypoint_suitability(W, np.zeros((0, 3)), 2.0, far_target, [0.0, 0, 5])
    np.testing.assert_allclose(S, suitability(2.0, 0.0))
    # near the target, a distance-reducing waypoint with a clear path gets +0.2
    S2 = waypoint_suitability(np.array([[1.0, 0, 5], [-1.0, 0, 5]]), np.zeros((0, 3)), 10.0, [8.0, 0, 5], [0.0, 0, 5])
    assert S2[0] == pytest.approx(min(1.0, suitability(10.0, 0.0) + 0.2))
    assert S2[1] == pytest.approx(suitability(10.0, 0.0))

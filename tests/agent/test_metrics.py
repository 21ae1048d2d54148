"""Metrics on hand-made cases with known answers."""

import numpy as np
import pytest

from cogmap.metrics import (
    CoverageTracker,
    ate_per_metre,
    coverage_efficiency,
    nauc,
    path_length,
    rmse,
    scan_mask,
)


def test_scan_polygon_fills_a_square_room():
    # 4 m x 4 m free room at 0.1 m cells; a "scan" from the centre hitting the four walls
    free = np.ones((40, 40), dtype=bool)
    corners = np.array([[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]])
    mask = scan_mask(free.shape, (0.0, 0.0), 0.1, corners)
    assert mask.sum() == pytest.approx(1600, rel=0.06)
    tracker = CoverageTracker(free, (0.0, 0.0), 0.1)
    half = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 4.0], [0.0, 4.0]])
    assert tracker.update(half) == pytest.approx(0.5, abs=0.03)
    assert tracker.update(half) == pytest.approx(0.5, abs=0.03)  # seeing it twice adds nothing
    assert tracker.update(corners) == pytest.approx(1.0, abs=0.01)
    assert tracker.area == pytest.approx(16.0, rel=0.01)


def test_path_and_efficiency():
    path = np.array([[0, 0], [3, 0], [3, 4]])
    assert path_length(path) == 7.0
    assert coverage_efficiency(14.0, 7.0) == 2.0
    assert coverage_efficiency(1.0, 0.0) == 0.0


def test_nauc_known_curves():
    assert nauc([0.0], [1.0], budget=10) == 1.0  # full coverage at once
    assert nauc([0.0, 5.0], [0.0, 1.0], budget=10) == 0.5  # full at half the budget
    assert nauc([0.0, 5.0, 20.0], [0.0, 0.5, 1.0], budget=10) == 0.25  # samples past the budget ignored
    with pytest.raises(ValueError):
        nauc([1.0, 0.5], [0.0, 1.0], 2.0)


def test_drift_errors():
    truth = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]])
    est = truth + np.array([0.0, 0.3])
    assert rmse(est, truth) == pytest.approx(0.3)
    assert ate_per_metre(est, truth) == pytest.approx(0.15)

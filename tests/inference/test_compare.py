"""The comparison harness."""

import numpy as np
from inference_helpers import pose_model, random_model

from cogmap.compare import Row, compare_inference, format_table, generate_sequence


def test_harness_runs_and_exact_has_zero_kl():
    m = random_model(0, sizes=(3, 2), modalities=((0,), (0, 1)))
    seq = generate_sequence(m, 6, seed=0)
    assert seq.states.shape == (6, 2) and len(seq.actions) == 5
    rows = compare_inference(m, seq.observations, seq.actions, true_states=seq.states)
    by = {r.scheme: r for r in rows}
    assert isinstance(rows[0], Row)
    assert {"exact", "fpi", "vmp", "mmp", "filter"} <= set(by)
    assert by["exact"].kl < 1e-12
    assert by["filter"].error and "single-factor" in by["filter"].error
    for name in ("fpi", "vmp", "mmp"):
        assert by[name].kl >= 0 and np.isfinite(by[name].free_energy)
        assert 0 <= by[name].accuracy <= 1 and by[name].ms_per_step > 0
    table = format_table(rows)
    assert "exact" in table and "KL" in table and "n/a" in table


def test_harness_single_factor_with_pose_and_window():
    m = pose_model(10, 1)
    seq = generate_sequence(m, 6, seed=1)
    assert len(seq.observations[0]) == 2  # view + metric pose
    rows = compare_inference(m, seq.observations, seq.actions, schemes=["exact", "filter", "fpi"], window=1)
    for r in rows:
        assert r.kl < 1e-10 and not r.error
        assert r.accuracy == 1.0  # against the exact MAP
    text = format_table(rows)
    assert text.count("\n") == 4

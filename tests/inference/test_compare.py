"""The comparison harness."""

import numpy as np
from inference_helpers import pose_model, random_model

from cogmap.inference.compare import Row, compare_inference, format_table, generate_sequence


def test_harness_runs_and_exact_has_zero_kl():
    m = random_model(0, sizes=(3, 2), modalities=((0,), (0, 1)))
    seq = generate_sequence(m, 6, seed=0)
    assert seq.states.shape == (6, 2) and len(seq.actions) == 5
    rows = compare_inference(m, seq.observations, seq.actions, true_states=seq.states)
    by = {r.scheme: r for r in rows}
    assert isinstance(rows[0], Row)
    # by default only the schemes that accept a two-factor Model: no filter, kernel or particle rows
    assert set(by) == {"exact", "fpi", "vmp", "vmp_pymdp", "mmp"} and not any(r.error for r in rows)
    assert by["exact"].kl < 1e-12
    for name in ("fpi", "vmp", "vmp_pymdp", "mmp"):
        assert by[name].kl >= 0 and np.isfinite(by[name].free_energy)
        assert 0 <= by[name].accuracy <= 1 and by[name].ms_per_step > 0
    assert "n/a" not in format_table(rows)
    # a scheme named explicitly still runs, and its refusal is a row with the reason
    asked = {r.scheme: r for r in compare_inference(m, seq.observations, seq.actions, schemes=["exact", "filter"])}
    assert asked["filter"].error and "single-factor" in asked["filter"].error
    table = format_table(list(asked.values()))
    assert "exact" in table and "KL" in table and "n/a" in table


def test_harness_single_factor_with_pose_and_window():
    m = pose_model(10, 1)
    seq = generate_sequence(m, 6, seed=1)
    assert len(seq.observations[0]) == 2  # view + metric pose
    rows = compare_inference(m, seq.observations, seq.actions, schemes=["exact", "filter", "fpi"], window=1)
    for r in rows:
        assert r.kl < 1e-10 and not r.error
        assert r.accuracy == 1.0  # against the exact MAP
    table, legend = format_table(rows).split("\n\n")
    assert table.count("\n") == 4 and "upper bound on -log p(o_1:T)" in legend


def test_no_scheme_reports_a_free_energy_below_exact_on_random_models():
    from inference_helpers import brute_force_log_evidence

    cases = [dict(sizes=(3,), modalities=((0,),)), dict(sizes=(3, 2), modalities=((0,), (0, 1))),
             dict(sizes=(2, 2, 2), modalities=((0, 1), (2,), (1, 2)))]
    for seed in range(4):
        for case in cases:
            m = random_model(seed, **case)
            seq = generate_sequence(m, 4, seed=seed)
            rows = {r.scheme: r for r in compare_inference(m, seq.observations, seq.actions)}
            prior = [m.live_D(f) for f in range(len(m.factors))]
            log_evidence = brute_force_log_evidence(m, prior, seq.observations, seq.actions)
            assert abs(rows["exact"].free_energy + log_evidence) < 1e-9  # exact: F = -log p(o_1:T)
            for name, r in rows.items():
                if not r.error:
                    assert r.free_energy >= rows["exact"].free_energy - 1e-9, (name, seed, case)


def test_window_free_energy_of_exact_smoothed_marginals_bounds_the_evidence():
    from inference_helpers import brute_force_log_evidence, brute_force_marginals

    from cogmap.inference import window_free_energy

    m = random_model(1, sizes=(4,), modalities=((0,),))
    seq = generate_sequence(m, 4, seed=2)
    prior = [m.live_D(0)]
    marg = brute_force_marginals(m, prior, seq.observations, seq.actions)
    F = window_free_energy(m, prior, seq.observations, seq.actions, marg)
    assert F >= -brute_force_log_evidence(m, prior, seq.observations, seq.actions) - 1e-12


def test_a_model_factory_comes_only_from_a_loaded_module(tmp_path, monkeypatch):
    """``--model module:function`` selects among the modules ``--plugin`` imported; any other module's
    name is refused and nothing is imported."""
    import sys

    import pytest

    from cogmap.genmodel import Model
    from cogmap.inference.compare import load_model

    (tmp_path / "cogmap_probe_factory.py").write_text(
        "import pathlib\npathlib.Path(__file__).with_name('imported').touch()\n"
        "from cogmap.genmodel.demo_models import tmaze\n\ndef make():\n    return tmaze()\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.delitem(sys.modules, "cogmap_probe_factory", raising=False)
    with pytest.raises(ValueError, match="is not a loaded plugin .*add --plugin cogmap_probe_factory"):
        load_model("cogmap_probe_factory:make")
    assert not (tmp_path / "imported").exists() and "cogmap_probe_factory" not in sys.modules
    import subprocess  # noqa: F401 - loaded, but not a plugin

    with pytest.raises(ValueError, match="is not a loaded plugin"):
        load_model("subprocess:Popen", plugins=["cogmap_probe_factory"])
    import cogmap_probe_factory  # noqa: F401 - what --plugin does

    assert isinstance(load_model("cogmap_probe_factory:make", plugins=["cogmap_probe_factory"]), Model)
    with pytest.raises(ValueError, match="has no function 'nothing'"):
        load_model("cogmap_probe_factory:nothing", plugins=["cogmap_probe_factory"])

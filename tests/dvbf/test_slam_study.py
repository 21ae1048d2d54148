"""``cogmap reproduce dvbf-slam``: plan, distinct keys, a tiny run, its report, and bad input."""

import numpy as np
import pytest

from cogmap.study import run_study
from cogmap.study.registry import run_specs, study_plan
from cogmap.study.runner import load_runs


def test_full_plan_is_six_mazes_by_four_traversals_with_distinct_keys():
    specs = run_specs(study_plan("dvbf-slam", "full"))
    assert len(specs) == 72 and len({s["key"] for s in specs}) == 72
    assert {s["method"] for s in specs} == {"online", "offline", "mcl"}
    offline = next(s for s in specs if s["method"] == "offline")["method_options"]["offline"]
    assert (offline["chunk"], offline["jitter"], offline["pf_sigma"]) == (5, 0.001, 0.01)  # Appendix B-I
    assert {s["env"] for s in specs} == {f"maze{m}" for m in range(1, 7)}
    assert all(s["steps"] == 3000 and s["params"]["pretrain_maze"] == 0 for s in specs)


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="pretrains"):
        study_plan("dvbf-slam", "tiny", envs=["maze0"])
    with pytest.raises(ValueError, match="maze<seed>"):
        study_plan("dvbf-slam", "tiny", envs=["house"])
    with pytest.raises(ValueError, match="methods are"):
        study_plan("dvbf-slam", "tiny", methods=["smoothing"])


@pytest.mark.heavy
def test_tiny_study_runs_resumes_and_reports(tmp_path):
    first = run_study("dvbf-slam", tmp_path, scale="tiny", progress=False)
    assert first["complete"] and first["runs"] == 3  # online, offline and the grid-MCL stand-in, one traversal
    stored = load_runs(tmp_path / "dvbf-slam")
    assert run_study("dvbf-slam", tmp_path, scale="tiny", progress=False)["runs"] == 3
    assert load_runs(tmp_path / "dvbf-slam") == stored  # nothing redone
    by_method = {r["spec"]["method"]: r["result"] for r in stored.values()}
    assert set(by_method) == {"online", "offline", "mcl"}
    # the same traversal (same maze, seed and noise), so the same path integration
    for m in ("offline", "mcl"):
        assert by_method["online"]["trajectory_digest"] == by_method[m]["trajectory_digest"]
        assert by_method["online"]["error_pi_final"] == pytest.approx(by_method[m]["error_pi_final"], abs=1e-5)
    for result in by_method.values():
        curve = np.array(result["error_curve"])
        assert curve.shape == (3,) and curve[0] < 1e-2  # every 10th of 30 steps; the start is known
        assert result["error_max"] >= curve.max() - 1e-5  # covers the sampled steps (stored rounded to 5 decimals)
    assert by_method["mcl"]["error_max"] < 0.01  # the true map keeps it on track over 30 steps
    table = (tmp_path / "dvbf-slam" / "table.md").read_text()
    assert "paper: online" in table and "0.03 ± 0.02" in table and "**Target (online):**" in table
    assert "**Target (offline):**" in table and "0.04 ± 0.02" in table and "not built" not in table
    assert "Cartographer stand-in" in table and "0.05 ± 0.04" in table
    assert (tmp_path / "dvbf-slam" / "error.png").is_file()

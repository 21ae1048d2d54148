"""``cogmap reproduce drone`` through the study machinery: specs, runs, resume, report."""

import json

import pytest

from cogmap.study.registry import run_specs, study_plan
from cogmap.study.runner import run_study
from cogmap.study.runs import strip_timings


def test_plan_and_specs():
    plan = study_plan("drone", "full")
    assert plan["seeds"] == list(range(149)) and plan["params"]["levels"] == ["continue", "end"]
    assert {"agent", "straight", "potential", "no_filter", "no_epistemic"} <= set(plan["methods"])
    specs = run_specs(study_plan("drone", "tiny"))
    assert len(specs) == 2 * 2 * 2 and len({s["key"] for s in specs}) == len(specs)
    with pytest.raises(ValueError, match="unknown drone method"):
        study_plan("drone", "tiny", methods=["teleport"])


def test_tiny_study_runs_resumes_and_reports(tmp_path):
    s1 = run_study("drone", tmp_path, scale="tiny", seeds=[8], progress=False)
    assert s1["complete"] and s1["runs"] == 4
    table = (tmp_path / "drone" / "table.md").read_text()
    assert "paper (AirSim, 149 episodes)" in table and "| agent | 1 | 100.0 | 100.0 |" in table
    assert (tmp_path / "drone" / "success.png").exists() and (tmp_path / "drone" / "table.csv").exists()
    runs = sorted((tmp_path / "drone" / "runs").glob("*.json"))
    before = {p.name: strip_timings(json.loads(p.read_text())["result"]) for p in runs}
    s2 = run_study("drone", tmp_path, scale="tiny", seeds=[8], progress=False)
    assert s2["complete"] and json.loads((tmp_path / "drone" / "study.json").read_text())["sessions"][-1]["ran"] == 0
    after = {p.name: strip_timings(json.loads(p.read_text())["result"]) for p in runs}
    assert before == after


def test_a_runs_key_holds_its_own_methods_settings():
    specs = run_specs(study_plan("drone", "tiny", methods=["agent", "agent_published", "potential"], seeds=[0]))
    opts = {s["method"]: s["method_options"]["policy"] for s in specs}
    assert opts["potential"]["policy"] == "potential" and "planner" not in opts["potential"]
    assert opts["agent"]["planner"]["novelty"] and not opts["agent_published"]["planner"]["novelty"]
    keys = {(s["method"], s["level"]): s["key"] for s in specs}
    assert keys[("agent", "continue")].split("__")[-1] != keys[("agent_published", "continue")].split("__")[-1]

"""Study runner: atomic per-run files, resume, executors give the same per-run results."""

import json

import pytest

from cogmap.cli import main as cli_main
from cogmap.study import run_study
from cogmap.study.registry import run_specs, study_plan
from cogmap.study.runner import load_runs
from cogmap.study.runs import strip_timings


def _body(table: str) -> str:
    """The table without the header line that reports wall-clock time."""
    return table[table.index("| "):]


def _results(study_dir):
    return {k: strip_timings(v["result"]) for k, v in load_runs(study_dir).items()}


def test_specs_are_unique_and_cover_the_plan():
    plan = study_plan("drift", "reduced")
    specs = run_specs(plan)
    assert len({s["key"] for s in specs}) == len(specs) == len(plan["envs"]) * len(plan["methods"]) * len(
        plan["seeds"]) * len(plan["params"]["levels"])
    with pytest.raises(ValueError):
        study_plan("nope")


def test_run_keys_change_with_every_setting_that_changes_a_run(monkeypatch):
    tiny, reduced = run_specs(study_plan("exploration", "tiny")), run_specs(study_plan("exploration", "reduced"))
    assert run_specs(study_plan("exploration", "tiny")) == tiny  # deterministic
    shared = {(s["env"], s["method"], s["seed"]) for s in tiny}
    red = {(s["env"], s["method"], s["seed"]): s["key"] for s in reduced}
    assert shared <= set(red) and not {s["key"] for s in tiny} & set(red.values())
    base = study_plan("exploration", "reduced", envs=["mini_warehouse"], seeds=[0], methods=["random"])
    key = run_specs(base)[0]["key"]
    for change in ({"steps": {"mini_warehouse": 41}}, {"scale": "full"}, {"coverage_level": 0.8},
                   {"success_rule": {**base["success_rule"], "collision_run": 6}}, {"stop_rule": "budget"}):
        assert run_specs({**base, **change})[0]["key"] != key, change
    drift = run_specs(study_plan("drift", "reduced"))
    assert len({s["key"] for s in drift}) == len(drift)
    severe = [s for s in drift if s["level"] == "severe"]
    assert all(s["noise"] == {"slip": 0.08, "heading_bias": 0.05} for s in severe)
    from cogmap.study import config

    monkeypatch.setitem(config.DRIFT_LEVELS, "severe", {"slip": 0.1, "heading_bias": 0.05})
    assert not {s["key"] for s in severe} & {s["key"] for s in run_specs(study_plan("drift", "reduced"))}
    monkeypatch.setitem(config.METHOD_OPTIONS, "random", {"note": "another option"})
    assert run_specs(base)[0]["key"] != key
    assert {s["method"] for s in drift} >= {"frontier", "frontier_paper"}
    with pytest.raises(ValueError):
        run_specs({**base, "methods": ["nope"]})


def test_tiny_then_reduced_in_one_directory_does_not_mix(tmp_path):
    kw = dict(envs=["mini_warehouse"], seeds=[0], methods=["random"], progress=False)
    tiny = run_study("exploration", tmp_path, scale="tiny", **kw)
    reduced = run_study("exploration", tmp_path, scale="reduced", **kw)
    assert tiny["runs"] == reduced["runs"] == 1 and not reduced["duplicates"]
    runs = load_runs(tmp_path / "exploration")
    assert len(runs) == 2  # both stay on disk ...
    assert sorted(r["result"]["steps"] for r in runs.values()) == [6, 40]
    assert "mini_warehouse 6." in tiny["table"] and "mini_warehouse 40." in reduced["table"]  # ... each table its own
    assert len(json.loads((tmp_path / "exploration" / "study.json").read_text())["sessions"]) == 1
    csv = (tmp_path / "exploration" / "runs.csv").read_text().splitlines()
    assert len(csv) == 2 and ",40," in csv[1]
    # a stored run whose spec differs from the plan's (same key) is not reused
    key = next(k for k, r in runs.items() if r["spec"]["scale"] == "reduced")
    path = tmp_path / "exploration" / "runs" / f"{key}.json"
    stored = json.loads(path.read_text())
    stored["spec"]["steps"] = 39
    path.write_text(json.dumps(stored))
    run_study("exploration", tmp_path, scale="reduced", **kw)
    assert json.loads(path.read_text())["spec"]["steps"] == 40


def test_the_same_run_twice_in_a_row_is_reported_as_an_error():
    from cogmap.study.report import distinct_check, protocol_note

    plan = study_plan("exploration", "tiny")

    def run(seed, method, digest):
        return {"key": f"k{seed}{method}", "spec": {"env": "mini_warehouse", "method": method, "seed": seed},
                "result": {"trajectory_digest": digest}}

    results = [run(0, "aimapp", "a"), run(1, "aimapp", "a"), run(2, "aimapp", "b"), run(0, "frontier", "a")]
    counts, dups = distinct_check(results)
    assert counts == {("mini_warehouse", "aimapp", None): 2, ("mini_warehouse", "frontier", None): 1}
    assert dups == [["k0aimapp", "k1aimapp"]]  # another method with the same path is another row
    assert "ERROR" in protocol_note(plan, results, "end")
    assert "ERROR" not in protocol_note(plan, results[1:], "end")


def test_resumed_study_gives_the_same_table_as_an_uninterrupted_one(tmp_path):
    kw = dict(scale="tiny", methods=["aimapp", "frontier", "random"], progress=False)
    whole = run_study("exploration", tmp_path / "whole", **kw)
    assert whole["complete"] and whole["runs"] == 6 and whole["duplicates"] == []
    assert "2 distinct run(s)" in whole["table"] and "ERROR" not in whole["table"]
    part = run_study("exploration", tmp_path / "part", limit=2, **kw)  # "interrupted" after two runs
    assert not part["complete"] and part["runs"] == 2
    runs_dir = tmp_path / "part" / "exploration" / "runs"
    first = sorted(runs_dir.glob("*.json"))[0]
    stamp = first.stat().st_mtime_ns
    resumed = run_study("exploration", tmp_path / "part", **kw)
    assert resumed["complete"]
    assert first.stat().st_mtime_ns == stamp, "a finished run must not be redone"
    assert _body(resumed["table"]) == _body(whole["table"])
    # lose one result file: only that run is redone, the table is unchanged
    first.unlink()
    again = run_study("exploration", tmp_path / "part", **kw)
    assert _body(again["table"]) == _body(whole["table"])
    assert _results(tmp_path / "part" / "exploration") == _results(tmp_path / "whole" / "exploration")
    meta = json.loads((tmp_path / "part" / "exploration" / "study.json").read_text())
    assert meta["complete"] and len(meta["sessions"]) == 3 and meta["versions"]["numpy"]
    for name in ("table.md", "table.csv", "runs.csv", "coverage_curves.png", "coverage_efficiency.png"):
        assert (tmp_path / "part" / "exploration" / name).exists()
    assert not list(runs_dir.glob(".*.tmp"))


def test_cli_entry_point(tmp_path, capsys):
    code = cli_main(["reproduce", "goals", "--scale", "tiny", "--seeds", "0", "--out", str(tmp_path), "--quiet"])
    assert code == 0
    out = capsys.readouterr().out
    assert "Executed vs. A*" in out


def test_dropout_study_pairs_each_fault_with_the_same_seed_without_one(tmp_path):
    out = run_study("dropout", tmp_path, scale="tiny", seeds=[0], progress=False)
    rows = {r["spec"]["level"]: r["result"] for r in load_runs(tmp_path / "dropout").values()}
    assert set(rows) == {"none", "lidar", "camera"}
    assert rows["none"]["silent_decisions"] == 0
    assert rows["lidar"]["silent_decisions"] == rows["camera"]["silent_decisions"] == 2
    assert "loss vs. no fault" in out["table"] and not out["duplicates"]


def test_a_table_names_which_methods_each_version_of_the_code_made():
    from cogmap.study.registry import code_versions

    results = [{"code": "aa", "spec": {"method": "aimapp"}}, {"code": "aa", "spec": {"method": "aimapp"}},
               {"code": "bb", "spec": {"method": "oracle"}}, {"code": "bb", "spec": {"method": "frontier"}}]
    assert code_versions(results, "aa") == "`aa` aimapp (2 runs)"
    assert code_versions(results, "bb") == "`bb` frontier (1 runs), oracle (1 runs)"

"""The generalisation study: its plan, its keys and one tiny run."""

import json

import numpy as np

from cogmap.agent.liveness import reachable_mask
from cogmap.envs.buildings import KINDS
from cogmap.study.config import building_envs
from cogmap.study.registry import run_specs, study_plan
from cogmap.study.runner import run_study


def test_plan_covers_twenty_buildings_three_seeds_and_four_methods():
    plan = study_plan("generalisation", "full")
    assert len(plan["envs"]) == 20 and plan["seeds"] == [0, 1, 2]
    assert plan["methods"] == ["aimapp", "frontier", "nbv", "oracle"]
    assert set(plan["steps"].values()) == {300}
    seeds = [int(e.split(":")[2]) for e in plan["envs"]]
    assert seeds == list(range(1000, 1020)) and min(seeds) >= 50  # the tests use building seeds 0-49
    assert [e.split(":")[1] for e in plan["envs"][:6]] == list(KINDS)  # kinds cycled
    reduced = study_plan("generalisation", "reduced")
    assert len(reduced["envs"]) == 4 and reduced["seeds"] == [0]


def test_keys_are_distinct_and_carry_every_setting():
    plan = study_plan("generalisation", "full")
    specs = run_specs(plan)
    assert len(specs) == 20 * 3 * 4 == len({s["key"] for s in specs})
    base = specs[0]
    for change in ({"steps": {**plan["steps"], base["env"]: 299}}, {"coverage_level": 0.8}):
        other = run_specs({**plan, **change})[0]
        assert other["key"] != base["key"] and other["key"].split("__")[:3] == base["key"].split("__")[:3]
    assert run_specs(study_plan("generalisation", "reduced"))[0]["key"] != base["key"]  # scale is in the key
    assert base["env"] in base["key"] and base["method"] in base["key"] and f"s{base['seed']}" in base["key"]
    # AIMAPP's runs carry the goal phase that follows exploring; the baselines' keys do not change with it
    goals = {s["method"]: s.get("goals") for s in specs}
    assert goals["aimapp"]["goals_per_run"] == 1 and goals["frontier"] is None and goals["oracle"] is None
    assert goals["nbv"] is None
    other = run_specs({**plan, "aimapp_goals": {**plan["aimapp_goals"], "goal_steps": 50}})
    changed = {s["method"] for s, t in zip(specs, other, strict=True) if s["key"] != t["key"]}
    assert changed == {"aimapp"}


def test_building_envs_cycle_kinds_from_the_first_seed():
    assert building_envs(8, 7) == [f"building:{KINDS[i % 6]}:{7 + i}" for i in range(8)]


def test_reachable_mask_follows_only_believed_transitions():
    # 0 -> 1 (0.9), 1 -> 2 (0.4: not believed), 2 -> 3 (0.9); one action, two slots
    succ = np.full((4, 1, 2), -1)
    prob = np.zeros((4, 1, 2))
    succ[0, 0, 0], prob[0, 0, 0] = 1, 0.9
    succ[1, 0, 0], prob[1, 0, 0] = 2, 0.4
    succ[2, 0, 0], prob[2, 0, 0] = 3, 0.9
    assert reachable_mask(succ, prob, 0, 4).tolist() == [True, True, False, False]
    assert reachable_mask(succ, prob, 2, 4).tolist() == [False, False, True, True]
    assert not reachable_mask(succ, prob, 5, 4).any()


def test_tiny_run_writes_rows_with_end_reasons(tmp_path):
    summary = run_study("generalisation", tmp_path, scale="tiny", methods=["aimapp", "oracle"], progress=False)
    assert summary["complete"] and summary["runs"] == 2 and not summary["duplicates"]
    runs = {p.stem.split("__")[1]: json.loads(p.read_text())
            for p in (tmp_path / "generalisation" / "runs").glob("*.json")}
    aim = runs["aimapp"]["result"]
    assert aim["steps"] == 6 and aim["end_reason"] == "budget"  # 6 decisions: the budget ends it
    assert isinstance(aim["unvisited_reachable"], int) and aim["unvisited_reachable"] >= 0
    assert runs["oracle"]["result"]["unvisited_reachable"] is None
    assert "goals" not in runs["oracle"]["result"]
    assert len(aim["goals"]) == 1  # the stored view farthest from the start, at most 5 decisions at tiny scale
    assert aim["goals"][0]["steps"] <= 5 and isinstance(aim["goals"][0]["reached"], bool)
    table = (tmp_path / "generalisation" / "table.md").read_text()
    assert "building:corridor:1000" in table and "All buildings pooled" in table and "Target" in table
    assert "Goal runs after exploring" in table

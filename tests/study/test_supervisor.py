"""Runs in supervised worker processes: a run past its time limit is stopped, recorded as failed
with its reason, and the study goes on; a later session retries it."""

from __future__ import annotations

import json

import pytest

from cogmap.study.runner import run_study
from cogmap.study.supervisor import run_supervised

pytest.importorskip("pybullet")


def test_a_run_past_its_time_limit_is_stopped_and_the_study_goes_on(tmp_path):
    # one worker, a limit far below one run's time: every run is stopped and recorded, none hangs
    kw = dict(scale="tiny", seeds=[0], envs=["mini_warehouse"], methods=["random"], progress=False)
    out = run_study("exploration", tmp_path, time_limit=0.05, **kw)
    assert not out["complete"] and out["runs"] == 0 and len(out["failed"]) == out["total"] >= 1
    failed = sorted((tmp_path / "exploration" / "failed").glob("*.json"))
    assert len(failed) == out["total"]
    record = json.loads(failed[0].read_text())
    assert "exceeded the time limit of 0.05 s" in record["reason"] and record["spec"]["key"] == record["key"]
    # a new session with room to finish retries them and clears the failure records
    again = run_study("exploration", tmp_path, time_limit=600, workers=2, **kw)
    assert again["complete"] and not again["failed"]
    assert not list((tmp_path / "exploration" / "failed").glob("*.json"))


def test_a_run_that_raises_is_recorded_with_its_error():
    done, failed = [], []
    specs = [{"key": "a"}, {"key": "b", "steps": -1}]
    run_supervised(int, specs, 1, 30.0, done.append, lambda spec, why: failed.append((spec["key"], why)))
    assert not done and [k for k, _ in failed] == ["a", "b"]
    assert all("TypeError" in why for _, why in failed)  # int(dict) raises in the worker, which goes on

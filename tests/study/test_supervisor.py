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


def test_two_studies_cannot_write_one_directory(tmp_path):
    import fcntl

    from cogmap.study.runner import StudyBusyError

    (tmp_path / "exploration").mkdir()
    with open(tmp_path / "exploration" / ".lock", "a+") as held:  # another process holds the study
        fcntl.flock(held, fcntl.LOCK_EX | fcntl.LOCK_NB)
        with pytest.raises(StudyBusyError, match="in use by another study"):
            run_study("exploration", tmp_path, scale="tiny", seeds=[0], envs=["mini_warehouse"],
                      methods=["random"], progress=False)


def test_ctrl_c_stops_a_study_quickly_keeps_finished_runs_and_leaves_no_process(tmp_path):
    import os
    import signal
    import subprocess
    import sys
    import time

    # 3 seeds: 36 tiny runs, so the study is still running when the first record appears (the 12 runs
    # of one seed take about 2 s, and once finished them all before the signal)
    cmd = [sys.executable, "-m", "cogmap.cli", "reproduce", "exploration", "--scale", "tiny", "--out",
           str(tmp_path), "--workers", "2", "--quiet", "--seeds", "0", "1", "2"]
    # the child gets Ctrl-C as from a terminal: if anything in this test process has set SIGINT to be
    # ignored, a child would inherit that and never see the signal
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    runs = tmp_path / "exploration" / "runs"
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and not (runs.exists() and any(runs.glob("*.json"))):
        time.sleep(0.2)
    kept_before = len(list(runs.glob("*.json")))
    assert kept_before >= 1 and proc.poll() is None, "the study should still be running"
    t0 = time.monotonic()
    os.killpg(proc.pid, signal.SIGINT)  # Ctrl-C reaches the whole foreground group
    proc.wait(timeout=30)
    # the study's own exit; helpers that share its pipes (multiprocessing's resource tracker) may close them
    # later, which the check for left-behind processes below covers
    stopped = time.monotonic() - t0
    _, err = proc.communicate(timeout=30)
    assert stopped < 10
    assert proc.returncode == 130 and "interrupted" in err and "Traceback" not in err
    assert len(list(runs.glob("*.json"))) >= kept_before  # finished runs are kept
    deadline = time.monotonic() + 15  # no worker left behind (an exited helper is reaped by init)
    while time.monotonic() < deadline:
        try:
            os.killpg(proc.pid, 0)
        except ProcessLookupError:
            break
        time.sleep(0.2)
    else:
        pytest.fail("processes of the study are still running 15 s after Ctrl-C")

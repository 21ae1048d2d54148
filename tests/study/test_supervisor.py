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


def _children(pid: int) -> set[int]:
    """The processes whose parent is ``pid`` (from /proc)."""
    from pathlib import Path

    found = set()
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            found.add(int(stat.parent.name))
    return found


def _alive(pid: int) -> bool:
    from pathlib import Path

    try:  # a zombie has finished: only its entry is left for its (new) parent to collect
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


@pytest.mark.skipif(not __import__("sys").platform.startswith("linux"), reason="reads /proc")
def test_workers_die_when_the_main_process_is_killed(tmp_path):
    import os
    import signal
    import subprocess
    import sys
    import time

    # a study's main process with two workers, each on a run of 60 s, killed with SIGKILL: it cannot
    # stop them itself, so they must notice on their own
    script = ("import time\nfrom cogmap.study.supervisor import run_supervised\n"
              "run_supervised(time.sleep, [60, 60], 2, None, print, print)\n")
    proc = subprocess.Popen([sys.executable, "-c", script], start_new_session=True)
    deadline = time.monotonic() + 60
    workers: set[int] = set()
    while time.monotonic() < deadline and len(workers) < 2:
        time.sleep(0.2)
        workers = {c for c in _children(proc.pid) if b"spawn_main" in open(f"/proc/{c}/cmdline", "rb").read()}
    assert len(workers) == 2, "the two workers should have started"
    time.sleep(1.0)  # both are inside their run
    others = _children(proc.pid) - workers
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait(timeout=10)
    deadline = time.monotonic() + 5
    while time.monotonic() < deadline and any(_alive(p) for p in workers | others):
        time.sleep(0.1)
    left = [p for p in workers | others if _alive(p)]
    for p in left:
        os.kill(p, signal.SIGKILL)
    assert not left, f"processes of the killed study still alive after 5 s: {left}"

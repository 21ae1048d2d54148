"""The Ray executor on a real multi-process cluster on loopback (a head and a second node, each
started by ``ray start`` as its own processes), reached through its address as ``--address`` does:
a study cut after one run and resumed completes with the same results as the local executor run
without a break, a run that hangs is recorded as failed at its time limit and one that raises with
its error, and the study goes on."""

from __future__ import annotations

import json
import os
import shutil
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

ray = pytest.importorskip("ray")
pytest.importorskip("pybullet")

from cogmap.study.ray_executor import run_ray  # noqa: E402
from cogmap.study.runner import load_runs, run_study  # noqa: E402
from cogmap.study.runs import strip_timings  # noqa: E402


def _results(study_dir):
    return {k: strip_timings(v["result"]) for k, v in load_runs(study_dir).items()}


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.heavy
def test_ray_executor_in_this_process_matches_the_local_one(tmp_path):
    """Ray started by the study itself (no address). Runs before the cluster below exists, so it
    cannot join it, and shares this file's worker with it under pytest-xdist."""
    kw = dict(scale="tiny", seeds=[0, 1], methods=["aimapp", "frontier"], progress=False, report=False)
    run_study("exploration", tmp_path / "local", workers=1, **kw)
    run_study("exploration", tmp_path / "ray", workers=2, executor="ray", **kw)
    local, ray_ = _results(tmp_path / "local" / "exploration"), _results(tmp_path / "ray" / "exploration")
    assert len(local) == 4 and local == ray_


@pytest.fixture(scope="module")
def cluster():
    cli = Path(sys.executable).with_name("ray")
    if not cli.exists():
        cli = shutil.which("ray")
    assert cli, "the ray command comes with the ray package"
    port = _free_port()
    address = f"127.0.0.1:{port}"
    # a short path: Ray's socket paths under it must stay within AF_UNIX's 107 bytes (pytest's are too long)
    temp = Path(tempfile.mkdtemp(prefix="ray", dir="/tmp"))
    common = ["--num-cpus", "1", "--disable-usage-stats"]
    # a loopback cluster of this test only: no token (the nodes and this process would need to share one)
    settings = {"RAY_AUTH_MODE": "disabled", "RAY_USAGE_STATS_ENABLED": "0"}
    env = {**os.environ, **settings, "PYTHONPATH": str(Path(__file__).resolve().parents[2])}
    mp = pytest.MonkeyPatch()
    for k, v in settings.items():
        mp.setenv(k, v)
    try:
        subprocess.run([str(cli), "start", "--head", "--node-ip-address", "127.0.0.1", "--port", str(port),
                        "--include-dashboard", "false", "--temp-dir", str(temp), *common],
                       check=True, capture_output=True, env=env, timeout=120)
        joined = subprocess.run([str(cli), "start", "--address", address, "--node-ip-address", "127.0.0.1",
                                 *common], capture_output=True, text=True, env=env, timeout=120)
        assert joined.returncode == 0, f"ray start --address failed: {joined.stderr[-2000:]}"
        deadline = time.monotonic() + 60
        while True:  # both nodes registered: 2 CPUs in the cluster
            out = subprocess.run([sys.executable, "-c", f"import ray; ray.init(address='{address}', "
                                  "log_to_driver=False); print(int(ray.cluster_resources().get('CPU', 0)))"],
                                 capture_output=True, text=True, env=env, timeout=60).stdout.strip()
            if out.endswith("2") or time.monotonic() > deadline:
                break
            time.sleep(1.0)
        assert out.endswith("2"), f"the second node did not join: {out!r}"
        yield address
    finally:
        subprocess.run([str(cli), "stop", "--force"], capture_output=True, env=env, timeout=120)
        mp.undo()
        shutil.rmtree(temp, ignore_errors=True)


def test_a_study_through_address_interrupted_and_resumed_matches_the_local_executor(cluster, tmp_path):
    kw = dict(scale="tiny", seeds=[0], envs=["mini_warehouse"], methods=["random", "frontier"], progress=False,
              report=False)
    run_study("exploration", tmp_path / "local", workers=1, **kw)
    ray_kw = dict(workers=2, executor="ray", address=cluster, time_limit=300, **kw)
    first = run_study("exploration", tmp_path / "ray", limit=1, **ray_kw)  # stopped after one run, as if cut
    assert not first["complete"] and first["runs"] == 1
    (kept,) = (tmp_path / "ray" / "exploration" / "runs").glob("*.json")
    stamp = kept.stat().st_mtime_ns
    out = run_study("exploration", tmp_path / "ray", **ray_kw)  # resumed: only the missing run is made
    assert out["complete"] and not out["failed"]
    assert kept.stat().st_mtime_ns == stamp
    sessions = json.loads((tmp_path / "ray" / "exploration" / "study.json").read_text())["sessions"]
    assert [s["ran"] for s in sessions] == [1, 1]

    local, remote = _results(tmp_path / "local" / "exploration"), _results(tmp_path / "ray" / "exploration")
    assert len(local) == 2 and local == remote


def test_a_hung_run_is_failed_at_its_limit_an_erring_one_with_its_error_and_the_rest_finish(cluster):
    done, failed = [], []
    t0 = time.monotonic()

    def nap(seconds):  # the run: 0.1 s twice, 600 s once (hangs), and a string (raises TypeError)
        time.sleep(seconds)

    run_ray(nap, [0.1, 600, "x", 0.1], 2, cluster, 5.0, done.append, lambda spec, why: failed.append((spec, why)))
    elapsed = time.monotonic() - t0
    assert done == [None, None]  # the two short runs finished
    assert sorted(spec for spec, _ in failed if spec != "x") == [600] and len(failed) == 2
    why = dict(failed)
    assert why[600] == "exceeded the time limit of 5 s"
    why = why["x"]
    assert why.startswith("TypeError") and "\n" not in why
    assert elapsed < 60  # nothing waited on the hung run

"""Run commands under a wall-clock limit (child process killed past it, failed.json written) and run
directories that are never silently overwritten (--force / --resume)."""

from __future__ import annotations

import json

import pytest

from cogmap.cli import main

pytest.importorskip("pybullet")


def _run(capsys, argv):
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def _interrupted_run(out, steps=300, at=5, every=2):
    """An exploration stopped by Ctrl-C after ``at`` decisions (checkpoints every ``every``)."""
    from unittest import mock

    from cogmap.explore import Done, explore

    real = Done.__call__

    def ctrl_c(self, decision):
        ended = real(self, decision)
        if self.agent.counts.steps == at:
            raise KeyboardInterrupt
        return ended

    with mock.patch.object(Done, "__call__", ctrl_c), pytest.raises(KeyboardInterrupt):
        explore("house", steps=steps, seed=0, out=out, progress=False, patience=0, checkpoint_every=every)


def test_explore_past_its_time_limit_is_killed_and_keeps_what_was_written(capsys, tmp_path):
    out = tmp_path / "run"
    _interrupted_run(out)
    # resumed for 300 decisions with a 1 s limit: the child is killed, the directory keeps its files
    code, _, err = _run(capsys, ["explore", "--out", str(out), "--resume", "--time-limit", "1", "--quiet"])
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err
    assert "run stopped: exceeded the time limit of 1 s" in err and "--resume continues it" in err
    failed = json.loads((out / "failed.json").read_text())
    assert failed["reason"] == "exceeded the time limit of 1 s" and failed["command"] == "cogmap explore"
    assert (out / "run.json").exists() and (out / "checkpoint" / "state.json").exists()


def test_dvbf_slam_past_its_time_limit_is_killed(capsys, tmp_path):
    out = tmp_path / "slam"
    code, _, err = _run(capsys, ["dvbf", "slam", "--steps", "5000", "--out", str(out), "--time-limit", "0.5",
                                 "--quiet"])
    assert code == 2 and "exceeded the time limit of 0.5 s" in err and err.count("\n") == 1
    assert json.loads((out / "failed.json").read_text())["command"] == "cogmap dvbf"


def test_a_command_within_its_limit_prints_its_result_from_the_child(capsys, tmp_path):
    out = tmp_path / "run"
    code, stdout, _ = _run(capsys, ["explore", "--steps", "2", "--out", str(out), "--quiet", "--time-limit", "600"])
    assert code == 0 and json.loads(stdout[: stdout.rindex("}") + 1])["steps"] == 2
    assert not (out / "failed.json").exists()


@pytest.mark.parametrize("argv, message", [
    (["explore"], "run directory is not empty; use --resume to continue the run it holds, or --force to clear it"),
    (["dvbf", "slam"],
     "run directory is not empty; use --force to clear it (--resume is not supported by cogmap dvbf)"),
])
def test_a_non_empty_run_directory_is_refused_naming_both_options(capsys, tmp_path, argv, message):
    (tmp_path / "old.txt").write_text("keep me")
    code, _, err = _run(capsys, [*argv, "--out", str(tmp_path), "--quiet"])
    assert code == 2 and err.strip().endswith(f"{tmp_path}: {message}") and err.count("\n") == 1
    assert (tmp_path / "old.txt").read_text() == "keep me"


def test_force_clears_the_directory_and_resume_is_refused_where_unsupported(capsys, tmp_path):
    (tmp_path / "stale").mkdir()
    (tmp_path / "stale" / "0041.png").write_text("stale")
    code, _, _ = _run(capsys, ["explore", "--steps", "2", "--out", str(tmp_path), "--force", "--quiet",
                               "--time-limit", "0"])
    assert code == 0 and not (tmp_path / "stale").exists() and (tmp_path / "metrics.json").exists()
    code, _, err = _run(capsys, ["goal", "--run", str(tmp_path), "--goal-obs", "0", "--resume", "--quiet"])
    assert code == 2 and "--resume is not supported by cogmap goal; start again with --force" in err
    code, _, err = _run(capsys, ["explore", "--out", str(tmp_path), "--resume", "--quiet", "--time-limit", "0"])
    assert code == 2 and "the run has finished (metrics.json); nothing to resume" in err


def test_an_interrupted_exploration_resumed_from_its_checkpoint_ends_as_an_uninterrupted_one(tmp_path):
    """Stopped after 11 decisions (last checkpoint at 8), resumed: the same trajectory, map and metrics
    as a run that was never stopped (seeded, with odometry drift so the simulator's generator matters)."""
    import csv
    from unittest import mock

    from cogmap.envs import OdometryNoise
    from cogmap.explore import Done, explore

    kw = dict(env="house", steps=20, seed=1, progress=False, patience=0, checkpoint_every=4,
              noise=OdometryNoise(slip=0.05, heading_bias=0.02))
    whole = explore(out=tmp_path / "whole", **kw)
    assert not (tmp_path / "whole" / "checkpoint").exists()  # removed once the run is written

    real = Done.__call__

    def ctrl_c_at_11(self, decision):
        ended = real(self, decision)
        if self.agent.counts.steps == 11:
            raise KeyboardInterrupt
        return ended

    with mock.patch.object(Done, "__call__", ctrl_c_at_11), pytest.raises(KeyboardInterrupt):
        explore(out=tmp_path / "cut", **kw)
    assert (tmp_path / "cut" / "checkpoint" / "model.npz").exists() and not (tmp_path / "cut" / "metrics.json").exists()
    resumed = explore(out=tmp_path / "cut", resume=True, progress=False)
    timing = ("decision_ms_mean", "decision_ms_p95")
    assert {k: v for k, v in resumed.items() if k not in timing} == {k: v for k, v in whole.items() if k not in timing}
    assert resumed["steps"] == 20 and resumed["num_states"] > 5

    def rows(run):
        with open(run / "trajectory.csv") as fh:
            return [{k: v for k, v in r.items() if k != "decision_ms"} for r in csv.DictReader(fh)]

    assert rows(tmp_path / "cut") == rows(tmp_path / "whole")
    names = [sorted(p.name for p in (tmp_path / run).iterdir()) for run in ("cut", "whole")]
    assert names[0] == names[1]
    assert json.loads((tmp_path / "cut" / "run.json").read_text())["resumed_at"] == [8]


def _manifest(**edit) -> dict:
    from dataclasses import asdict

    from cogmap.agent.config import AgentConfig
    from cogmap.envs import OdometryNoise

    d = {"command": "explore", "env": "mini_warehouse", "steps": 5, "seed": 0, "patience": 20,
         "checkpoint_every": 10, "config": AgentConfig().to_dict(), "noise": asdict(OdometryNoise())}
    d.update(edit)
    return d


@pytest.mark.parametrize("edit, message", [
    (dict(steps=-5), "steps: expected an integer in 1..100000 (MAX_DECISIONS), got -5"),
    (dict(steps=2.5), "steps: expected an integer in 1..100000 (MAX_DECISIONS), got 2.5"),
    (dict(seed="0"), "seed: expected an integer in 0..2147483647 (MAX_SEED), got \"0\""),
    (dict(patience=None), "patience: expected an integer in 0..100000 (MAX_DECISIONS), got null"),
    (dict(checkpoint_every=0), "checkpoint_every: expected an integer in 1..100000 (MAX_DECISIONS), got 0"),
    (dict(env=5), "env: expected a string, got 5"),
    (dict(env="cogmap/DroneField-v0"), "env: cogmap/DroneField-v0 is not a room for cogmap explore"),
    (dict(config=[1]), "config: expected an object of AgentConfig fields, got [1]"),
    (dict(config={"collision_preference": "low"}),
     "config: AgentConfig.collision_preference: expected a finite number, got 'low'"),
    (dict(config={"batch": 8}), "config: AgentConfig: unknown field(s) 'batch'"),
    (dict(noise={"slip": -5}), "noise: OdometryNoise.slip: must be a finite number in [-0.5, 0.5] (MAX_SLIP), got -5"),
    (dict(noise={"grip": 1}), "noise: unknown field(s) 'grip'"),
    (dict(noise=None), "noise: expected an object of OdometryNoise fields, got null"),
])
def test_resume_refuses_a_run_json_field_of_the_wrong_type_or_range(capsys, tmp_path, edit, message):
    (tmp_path / "run.json").write_text(json.dumps(_manifest(**edit)))
    code, _, err = _run(capsys, ["explore", "--out", str(tmp_path), "--resume", "--quiet", "--time-limit", "0"])
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err
    assert err.strip().startswith(f"cogmap explore: error: {tmp_path}/run.json: {message}"), err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.json"]  # nothing written as if it had run


def test_resume_refuses_a_missing_run_json_field(capsys, tmp_path):
    d = _manifest()
    del d["seed"]
    (tmp_path / "run.json").write_text(json.dumps(d))
    code, _, err = _run(capsys, ["explore", "--out", str(tmp_path), "--resume", "--quiet", "--time-limit", "0"])
    assert code == 2 and err.strip().endswith(f"{tmp_path}/run.json: missing field 'seed'")


def test_a_run_stopped_by_its_time_limit_says_what_resume_can_do_and_that_holds(capsys, tmp_path):
    """Killed 0.3 s after the start the child has not written run.json yet (it does so first, before
    the simulator and the agent exist): the message says --resume cannot continue it, and --resume
    indeed refuses while --force starts it again. Had it got further, the message would promise
    --resume, and that is checked instead."""
    out = tmp_path / "run"
    code, _, err = _run(capsys, ["explore", "--steps", "3", "--out", str(out), "--time-limit", "0.3", "--quiet"])
    assert code == 2 and err.count("\n") == 1 and "exceeded the time limit of 0.3 s" in err
    if (out / "run.json").exists():
        assert err.strip().endswith("(--resume continues it)")
        code, _, _ = _run(capsys, ["explore", "--out", str(out), "--resume", "--quiet", "--time-limit", "0"])
        assert code == 0 and json.loads((out / "metrics.json").read_text())["steps"] == 3
        return
    assert err.strip().endswith("(--resume cannot continue it: it stopped before writing run.json; start it again "
                                "with --force)")
    code, _, err = _run(capsys, ["explore", "--out", str(out), "--resume", "--quiet", "--time-limit", "0"])
    assert code == 2 and err.strip().endswith(f"{out}: no readable run.json to resume from")
    code, _, _ = _run(capsys, ["explore", "--steps", "2", "--out", str(out), "--force", "--quiet", "--time-limit", "0"])
    assert code == 0 and json.loads((out / "metrics.json").read_text())["steps"] == 2


def test_a_run_stopped_before_its_first_checkpoint_resumes_from_the_start(capsys, tmp_path):
    """run.json is written when the run starts: stopped before any checkpoint, --resume (as the
    message of a stopped run promises) runs it from the start with its recorded settings."""
    from cogmap.explore import resume_state

    out = tmp_path / "run"
    _interrupted_run(out, steps=3, at=1, every=10)
    assert (out / "run.json").exists() and not (out / "checkpoint").exists()
    assert resume_state(out) == " (--resume continues it)"
    code, _, _ = _run(capsys, ["explore", "--out", str(out), "--resume", "--quiet", "--time-limit", "0"])
    assert code == 0 and json.loads((out / "metrics.json").read_text())["steps"] == 3
    assert resume_state(out).startswith(" (it had written its results")

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


def test_explore_past_its_time_limit_is_killed_and_keeps_what_it_wrote(capsys, tmp_path):
    out = tmp_path / "run"
    code, _, err = _run(capsys, ["explore", "--env", "house", "--steps", "300", "--patience", "0", "--out", str(out),
                                 "--time-limit", "1", "--quiet"])
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err
    assert "run stopped: exceeded the time limit of 1 s" in err
    failed = json.loads((out / "failed.json").read_text())
    assert failed["reason"] == "exceeded the time limit of 1 s" and failed["command"] == "cogmap explore"
    assert (out / "run.json").exists()  # what the child wrote before it was killed is kept


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

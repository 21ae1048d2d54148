"""Every command-line error is one line naming the problem with exit status 2; --debug shows the
traceback instead; --version prints the version."""

import subprocess
import sys

import pytest

from cogmap import __version__
from cogmap.cli import main


def _one_line_error(capsys, argv) -> str:
    try:
        code = main(argv)
    except SystemExit as stop:  # argparse refusals
        code = stop.code
    out, err = capsys.readouterr()
    assert code == 2, (code, out, err)
    assert err.count("\n") == 1 and "Traceback" not in err, err
    return err.strip()


@pytest.mark.parametrize("argv, message", [
    (["explore", "--steps", "0"], "cogmap explore: error: argument --steps: must be at least 1, got 0"),
    (["explore", "--steps", "-1"], "argument --steps: must be at least 1, got -1"),
    (["explore", "--patience", "-5"], "argument --patience: must be at least 0, got -5"),
    (["explore", "--steps", "ten"], "argument --steps: expected an integer, got 'ten'"),
    (["goal", "--run", "x", "--goal-obs", "0", "--steps", "0"], "argument --steps: must be at least 1, got 0"),
    (["compare-inference", "--steps", "0"], "argument --steps: must be at least 1, got 0"),
    (["reproduce", "exploration", "--workers", "0"], "argument --workers: must be at least 1, got 0"),
    (["drone", "fly", "--episodes", "0"], "argument --episodes: must be at least 1, got 0"),
    (["no-such-command"], "cogmap: error: argument command: invalid choice: 'no-such-command'"),
    # every numeric flag is checked at parse time: finite, in its range, below its documented limit
    (["explore", "--slip", "-5"], "argument --slip: must be >= -0.5 and <= 0.5 (MAX_SLIP), got -5"),
    (["explore", "--heading-bias", "nan"], "argument --heading-bias: must be a finite number, got nan"),
    (["explore", "--seed", "-1"], "argument --seed: must be at least 0, got -1"),
    (["explore", "--steps", "100001"], "argument --steps: must be at most 100000 (MAX_DECISIONS), got 100001"),
    (["explore", "--checkpoint-every", "0"], "argument --checkpoint-every: must be at least 1, got 0"),
    (["explore", "--time-limit", "nan"], "argument --time-limit: must be a finite number >= 0, got nan"),
    (["goal", "--run", "x", "--goal-obs", "-2"], "argument --goal-obs: must be at least 0, got -2"),
    (["compare-inference", "--steps", "100000000"],
     "argument --steps: must be at most 1000 (cogmap.inference.compare.MAX_STEPS), got 100000000"),
    (["compare-inference", "--seed", "1e3"], "argument --seed: expected an integer, got '1e3'"),
    (["reproduce", "exploration", "--seeds", "-1"], "argument --seeds: must be at least 0, got -1"),
    (["reproduce", "exploration", "--seeds", "3", "2147483648"],
     "argument --seeds: must be at most 2147483647 (MAX_SEED), got 2147483648"),
    (["reproduce", "exploration", "--seeds"], "argument --seeds: expected at least one argument"),
    (["drone", "fly", "--episodes", "100001"], "argument --episodes: must be at most 100000 (MAX_EPISODES)"),
    (["drone", "fly", "--seed", "-3"], "argument --seed: must be at least 0, got -3"),
    (["dvbf", "slam", "--pretrain-maze", "-2"], "argument --pretrain-maze: must be at least -1, got -2"),
    (["dvbf", "slam", "--steps", "1000000000"], "argument --steps: must be at most 200000 (MAX_DVBF_STEPS)"),
    (["dvbf", "navigate", "--pairs", "601"], "argument --pairs: must be at most 600 (MAX_PAIRS), got 601"),
    (["dvbf", "explore", "--maze", "0"], "argument --maze: must be at least 1, got 0"),
])
def test_bad_arguments_are_one_line(capsys, argv, message):
    assert message in _one_line_error(capsys, argv)


def test_errors_inside_a_command_are_one_line_unless_debug(capsys, tmp_path):
    missing = tmp_path / "absent"
    err = _one_line_error(capsys, ["goal", "--run", str(missing), "--goal-obs", "0"])
    assert err == f"cogmap goal: error: {missing}/run.json: No such file or directory"
    err = _one_line_error(capsys, ["compare-inference", "--model", str(missing) + ".npz"])
    assert err.startswith("cogmap compare-inference: error: ") and "file not found" in err
    with pytest.raises(FileNotFoundError):
        main(["--debug", "goal", "--run", str(missing), "--goal-obs", "0"])


@pytest.mark.parametrize("env, message", [
    ("cogmap/DroneField-v0", "cogmap/DroneField-v0 is not a room for cogmap explore: it is the drone's 3D obstacle "
                             "field; fly it with 'cogmap drone fly'"),
    ("cogmap/LidarMaze-v0", "cogmap/LidarMaze-v0 is not a room for cogmap explore: it is the DVBF-LM LiDAR maze; "
                            "run it with 'cogmap dvbf slam', 'cogmap dvbf navigate' or 'cogmap dvbf explore'"),
    ("notes.txt", "notes.txt: not a layout file cogmap reads; --env reads a .json building or a .png plan"),
])
def test_an_environment_explore_does_not_run_says_what_does(capsys, tmp_path, env, message):
    err = _one_line_error(capsys, ["explore", "--env", env, "--out", str(tmp_path / "run"), "--quiet"])
    assert err.startswith(f"cogmap explore: error: {message}"), err
    assert not (tmp_path / "run").exists()  # refused before anything started


@pytest.mark.parametrize("manifest, kind", [
    ({"command": "drone fly", "seed": 0, "episodes": 1}, "a drone fly run"),
    ({"command": "dvbf slam", "config": {"batch": 8}, "maze_seed": 1}, "a dvbf slam run"),
    ({"seed": 0}, "not an exploration run (its run.json names no command)"),
])
def test_goal_on_another_kind_of_run_says_what_it_is(capsys, tmp_path, manifest, kind):
    import json

    (tmp_path / "run.json").write_text(json.dumps(manifest))
    err = _one_line_error(capsys, ["goal", "--run", str(tmp_path), "--goal-obs", "0", "--quiet"])
    assert err == f"cogmap goal: error: {tmp_path} is {kind}; goal needs an exploration run (cogmap explore)"
    assert not (tmp_path / "goal").exists()


def test_ray_executor_without_ray_says_how_to_install(capsys, tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "ray", None)  # as if Ray were not installed
    err = _one_line_error(capsys, ["reproduce", "exploration", "--scale", "tiny", "--executor", "ray",
                                   "--out", str(tmp_path), "--quiet"])
    assert "Ray, which is not installed; install it with: pip install 'cogmap[ray]'" in err
    assert not any(tmp_path.iterdir())  # refused before anything was written


def test_version(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["--version"])
    assert stop.value.code == 0 and capsys.readouterr().out.strip() == f"cogmap {__version__}"


def test_console_entry_point_prints_no_traceback():
    run = subprocess.run([sys.executable, "-m", "cogmap.cli", "explore", "--steps", "0"],
                         capture_output=True, text=True, timeout=60)
    assert run.returncode == 2
    assert run.stderr == "cogmap explore: error: argument --steps: must be at least 1, got 0\n"

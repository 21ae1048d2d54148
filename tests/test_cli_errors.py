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

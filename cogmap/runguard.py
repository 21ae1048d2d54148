"""What every run command shares: a wall-clock limit and run directories that lose nothing.

``cogmap explore``, ``goal``, ``drone fly`` and ``dvbf slam`` take

- ``--time-limit SECONDS`` (default :data:`DEFAULT_TIME_LIMIT_S`; 0 = none): the command runs in
  a child process supervised as study runs are (:func:`cogmap.study.supervisor.run_one`); past the
  limit the child is killed (a native call that never returns cannot be interrupted from inside),
  the run directory keeps what was written, ``failed.json`` records why, and the command ends with
  one line and a non-zero exit status; for a command that can resume, the line says whether
  ``--resume`` can continue the run in the state it was stopped in (:func:`resume_hint`).
  ``--debug`` runs the command in this process instead (so the traceback and a debugger reach the
  error), without the limit.
- ``--force`` / ``--resume``: a non-empty run directory is refused unless ``--force`` (clear it
  first) or ``--resume`` (continue the run it holds; only where the command supports it).
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import shutil
import sys
import time
from pathlib import Path

from .argtypes import nonnegative_float

DEFAULT_TIME_LIMIT_S = 1800.0
FAILED = "failed.json"


class RunDirError(ValueError):
    """A run directory that cannot be used as asked (not empty, not a directory, ...)."""


class RunFailed(RuntimeError):
    """A supervised command that exceeded its time limit, died or was interrupted."""


def add_run_options(parser, resume_help: str | None = None) -> None:
    """Add ``--time-limit``, ``--force`` and ``--resume`` to a command's parser.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The command's (sub)parser; it also gets the default ``resumable`` (whether ``resume_help``
        was given), read by :func:`run_command`.
    resume_help : str or None, optional
        Help text of ``--resume`` for a command that can resume a run; None (default): the
        command cannot, and ``--resume`` is refused with a message when given.
    """
    parser.add_argument("--time-limit", type=nonnegative_float, default=DEFAULT_TIME_LIMIT_S, metavar="SECONDS",
                        help=f"stop the run after this many seconds of wall-clock time, keep what it wrote and "
                             f"record the reason in {FAILED} (default: {DEFAULT_TIME_LIMIT_S:g}; 0: no limit)")
    parser.add_argument("--force", action="store_true", help="clear a non-empty run directory before writing")
    parser.add_argument("--resume", action="store_true",
                        help=resume_help or "not supported by this command (refused with a message)")
    parser.set_defaults(resumable=resume_help is not None)


def _protected(path: Path) -> bool:
    """Directories ``--force`` never clears: the root, the home directory, the working directory or
    any of its parents."""
    path = path.resolve()
    cwd = Path.cwd().resolve()
    return path == Path(path.anchor) or path == Path.home().resolve() or path == cwd or path in cwd.parents


def prepare_out(out: Path | None, command: str, force: bool, resume: bool, resumable: bool) -> None:
    """Check (and with ``force`` clear) the run directory before anything runs.

    Parameters
    ----------
    out : pathlib.Path or None
        The run directory; None when the command writes none (only the flags are checked).
    command : str
        Command name, for the messages.
    force : bool
        Clear a non-empty directory (never the root, the home directory, the working directory or
        one of its parents).
    resume : bool
        Continue the run the directory holds: it must not be empty; its ``failed.json`` is removed.
    resumable : bool
        Whether the command supports ``resume``.

    Raises
    ------
    RunDirError
        On ``resume`` for a command that cannot resume, ``resume`` with ``force``, ``out`` that is
        a file, nothing to resume, a non-empty directory without ``force`` or ``resume``, or a
        protected directory to clear.
    """
    if resume and not resumable:
        raise RunDirError(f"--resume is not supported by {command}; start again with --force")
    if resume and force:
        raise RunDirError("--resume and --force exclude each other (continue the run, or clear it)")
    if out is None:
        return
    if out.exists() and not out.is_dir():
        raise RunDirError(f"{out}: exists and is not a directory")
    busy = out.is_dir() and any(out.iterdir())
    if resume:
        if not busy:
            raise RunDirError(f"{out}: nothing to resume (the directory is empty or missing)")
        (out / FAILED).unlink(missing_ok=True)  # the failure it recorded is being dealt with
        return
    if not busy:
        return
    if not force:
        extra = "--resume to continue the run it holds, or --force to clear it" if resumable else \
            f"--force to clear it (--resume is not supported by {command})"
        raise RunDirError(f"{out}: run directory is not empty; use {extra}")
    if _protected(out):
        raise RunDirError(f"{out}: refusing to clear this directory with --force (use a run directory of its own)")
    for child in out.iterdir():
        if child.is_dir() and not child.is_symlink():
            shutil.rmtree(child)
        else:
            child.unlink()


def write_failed(out: Path | None, command: str, reason: str, **fields) -> None:
    """Write ``failed.json`` in the run directory: why the run stopped (what was written is kept).

    Parameters
    ----------
    out : pathlib.Path or None
        The run directory (created if missing); None: nothing is written.
    command : str
        Command name.
    reason : str
        Why the run stopped, one line.
    **fields
        Further JSON-serialisable entries (e.g. ``time_limit_s``).

    Notes
    -----
    The record also holds the UTC time it was written (``time``, ISO 8601).
    """
    if out is None:
        return
    out.mkdir(parents=True, exist_ok=True)
    record = {"command": command, "reason": reason, "time": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
              **fields}
    (out / FAILED).write_text(json.dumps(record, indent=1))


def _child(spec: dict) -> dict:
    """Runs in the supervised worker: the command itself, its stdout captured for the parent."""
    import threading

    from tqdm import tqdm

    from .argtypes import one_line
    from .plugins import import_plugins

    # a thread lock for the progress bars: tqdm's default includes a semaphore that a killed child
    # would leave registered (the resource tracker then warns at exit)
    tqdm.set_lock(threading.RLock())
    args = spec["args"]
    import_plugins(getattr(args, "plugin", ()))  # the user's registrations (cogmap --plugin), in this process too
    buf = io.StringIO()
    try:
        with contextlib.redirect_stdout(buf):
            code = args.func(args)
        return {"code": code, "stdout": buf.getvalue()}
    except Exception as err:  # noqa: BLE001 - reported to the parent as one line
        return {"error": one_line(err), "stdout": buf.getvalue()}


def run_command(args, command: str, out: Path | None) -> int:
    """Prepare the run directory, then run ``args.func(args)`` under the time limit.

    Calls ``args.precheck(args)`` when the parser set one, then :func:`prepare_out`. Without a
    limit (0) or with ``--debug`` the command runs in this process; otherwise in a supervised
    child (:func:`cogmap.study.supervisor.run_one`) whose captured stdout is echoed here.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments with ``func``, ``time_limit`` (seconds), ``force``, ``resume`` and
        ``resumable`` (see :func:`add_run_options`); optionally ``debug``, ``precheck`` and
        ``plugin`` (modules imported in the child too).
    command : str
        Command name, for messages and ``failed.json``.
    out : pathlib.Path or None
        The run directory, or None when the command writes none.

    Returns
    -------
    int
        The command's exit status (what ``args.func`` returned).

    Raises
    ------
    RunDirError
        From :func:`prepare_out`.
    RunFailed
        When the supervised command raised (recorded in ``failed.json`` if the run directory has
        content), exceeded the limit or died (always recorded); the message says what was kept.
    KeyboardInterrupt
        Re-raised after recording the interruption in ``failed.json``.
    """
    from .study.supervisor import run_one

    if args.resume and not args.resumable:  # before the command's own checks: the flag is the mistake
        raise RunDirError(f"--resume is not supported by {command}; start again with --force")
    check = getattr(args, "precheck", None)
    if check is not None:  # bad input is refused here, before a child starts or a directory is touched
        check(args)
    prepare_out(out, command, args.force, args.resume, args.resumable)
    limit = args.time_limit
    if not limit or getattr(args, "debug", False):
        return args.func(args)
    try:
        local = ("out_dir", "precheck", "resume_state")  # functions of the parser, not picklable
        plain = argparse.Namespace(**{k: v for k, v in vars(args).items() if k not in local})
        ok, result = run_one(_child, {"args": plain}, limit)
    except KeyboardInterrupt:
        write_failed(out, command, "interrupted (Ctrl-C)", time_limit_s=limit)
        raise
    if ok:
        sys.stdout.write(result["stdout"])
        if "error" in result:
            if out is not None and out.is_dir() and any(out.iterdir()):
                write_failed(out, command, result["error"], time_limit_s=limit)
            raise RunFailed(result["error"])
        return result["code"]
    reason = result
    again = resume_hint(args, out)
    write_failed(out, command, reason, time_limit_s=limit)
    kept = f"; what it wrote is kept in {out} ({FAILED} says why)" if out is not None else ""
    raise RunFailed(f"run stopped: {reason}{kept}{again}")


def resume_hint(args, out: Path | None) -> str:
    """The end of the message of a stopped run: what ``--resume`` can do with what was kept.

    A command that can resume may set the parser default ``resume_state`` to a function of the
    run directory returning that text (what its ``--resume`` needs is then checked, e.g. explore's
    ``run.json``); otherwise ``" (--resume continues it)"``. Empty for a command that cannot
    resume or writes no run directory.

    Parameters
    ----------
    args
        The command's parsed arguments.
    out
        The run directory, or None.

    Returns
    -------
    str
        The text to append to the one-line message.
    """
    if not getattr(args, "resumable", False) or out is None:
        return ""
    state = getattr(args, "resume_state", None)
    return state(Path(out)) if state is not None else " (--resume continues it)"

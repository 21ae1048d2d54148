"""Run a study: every run once, in parallel, resumable; then tables, CSV, figures, study.json.

Layout of ``<out>/<study>/``::

    runs/<key>.json   one finished run each (written to a temporary file, then os.replace)
    study.json        plan, seeds, package versions, git commit, wall-clock times
    table.md, table.csv, *.png

A run whose JSON exists is never redone, so an interrupted study resumes where it stopped.
Executors: ``local`` (supervised worker processes, :mod:`.supervisor`; ``workers=1`` without a
time limit runs in-process) or ``ray`` (each run a Ray task, :mod:`.ray_executor`;
``ray.init(address=...)``), with the same time limit and failure records; results are the same
per seed.
"""

from __future__ import annotations

import argparse
import contextlib
import fcntl
import json
import os
import sys
import time
from pathlib import Path

from ..argtypes import OneLineParser, positive_float, positive_int, seed_int
from .ray_executor import require_ray, run_ray
from .registry import execute, run_specs, studies, study_plan, write_report
from .supervisor import run_supervised


def write_json_atomic(path: Path, data) -> None:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    with open(tmp, "w") as fh:
        json.dump(data, fh, indent=1, allow_nan=False)
        fh.flush()
        os.fsync(fh.fileno())
    os.replace(tmp, path)


def same_spec(stored, spec: dict) -> bool:
    """A stored run is reused only when its spec equals this one exactly (after a JSON round trip)."""
    return stored == json.loads(json.dumps(spec))


def load_runs(study_dir: Path) -> dict[str, dict]:
    out = {}
    for p in sorted((Path(study_dir) / "runs").glob("*.json")):
        try:
            out[p.stem] = json.loads(p.read_text())
        except (OSError, json.JSONDecodeError):  # a torn file cannot exist (atomic), but be safe
            continue
    return out


def _run_local(specs, workers: int, sink, fail, time_limit: float | None) -> None:
    if workers <= 1 and time_limit is None:
        for s in specs:
            sink(execute(s))
        return
    run_supervised(execute, specs, workers, time_limit, sink, fail)


def _run_ray(specs, workers: int, address: str | None, sink, fail, time_limit: float | None) -> None:
    run_ray(execute, specs, workers, address, time_limit, sink, fail)


def run_study(name: str, out_dir="results", seeds=None, envs=None, methods=None, scale: str = "reduced",
              workers: int = 1, executor: str = "local", address: str | None = None, limit: int | None = None,
              progress: bool = True, report: bool = True, time_limit: float | None = None) -> dict:
    """Run (or resume) study ``name`` under ``out_dir/name``.

    Finished runs are kept and skipped; an exclusive lock stops two studies writing one directory.

    Parameters
    ----------
    name : str
        A registered study (:func:`cogmap.study.registry.studies`): ``"exploration"``,
        ``"success"``, ``"goals"``, ``"drift"``, ``"slip"``, ``"dropout"``, ``"obstacle"``,
        ``"scaling"``, ``"generalisation"``, ``"drone"``, ``"dvbf-navigation"``,
        ``"dvbf-exploration"``, ``"dvbf-slam"``, or one added with ``register_study``.
    out_dir : str or path-like, optional
        Parent directory of the study directory, default ``"results"``.
    seeds, envs, methods : sequence, optional
        Restrict the study's seeds, environments and methods.
    scale : str, optional
        ``"reduced"`` (default), ``"full"`` or ``"tiny"``.
    workers : int, optional
        Parallel workers, default 1.
    executor : str, optional
        ``"local"`` (processes, default) or ``"ray"``.
    address : str, optional
        Address of a running Ray cluster.
    limit : int, optional
        Run at most that many of the missing runs (then stop, as if interrupted).
    progress : bool, optional
        Show progress, default True.
    report : bool, optional
        Write the report table when there are results, default True.
    time_limit : float, optional
        Seconds per run: each run goes to a worker process (a Ray task with the ``ray`` executor,
        :mod:`cogmap.study.ray_executor`) that is killed past the limit; the run is recorded in
        ``failed/<key>.json`` with its reason, the study goes on, and a later session retries it. A
        run that raises is recorded the same way, with both executors. Without a limit and with one
        worker, local runs go in-process.

    Returns
    -------
    dict
        ``study_dir``, ``complete``, ``runs``, ``total``, ``wall_s``, ``failed``, ``duplicates`` and,
        with a report, ``table``.

    Raises
    ------
    ValueError
        For an unknown study or scale.
    RuntimeError
        If the Ray executor is asked for without ``ray`` installed.
    StudyBusyError
        If another process is running a study in that directory.
    """
    if executor == "ray":
        require_ray()  # before any directory is made
    plan = study_plan(name, scale, envs=envs, seeds=seeds, methods=methods)
    specs = run_specs(plan)
    study_dir = Path(out_dir) / name
    runs_dir = study_dir / "runs"
    runs_dir.mkdir(parents=True, exist_ok=True)
    with _locked(study_dir):
        return _run_study(name, study_dir, runs_dir, plan, specs, workers, executor, address, limit, progress,
                          report, time_limit)


class StudyBusyError(RuntimeError):
    """Another process is running a study in this directory."""


@contextlib.contextmanager
def _locked(study_dir: Path):
    """An exclusive lock on ``study_dir/.lock`` for the whole session (released when the process
    ends, however it ends), so two studies never write one directory."""
    fh = open(study_dir / ".lock", "a+")
    try:
        try:
            fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise StudyBusyError(f"{study_dir} is in use by another study; wait for it to finish "
                                 "or choose another --out") from None
        yield
    finally:
        fh.close()


def _run_study(name, study_dir, runs_dir, plan, specs, workers, executor, address, limit, progress, report,
               time_limit) -> dict:
    from tqdm import tqdm

    from cogmap.runs import git_commit, versions

    stored = load_runs(study_dir)  # files of other scales or settings stay, but are never used here
    done = {s["key"]: stored[s["key"]] for s in specs
            if s["key"] in stored and same_spec(stored[s["key"]].get("spec"), s)}
    todo = [s for s in specs if s["key"] not in done]
    missing = len(todo)
    if limit is not None:
        todo = todo[:limit]
    t0 = time.perf_counter()
    bar = tqdm(total=len(specs), initial=len(specs) - missing,
               disable=not progress, desc=f"{name} runs", unit="run")

    failed: dict[str, str] = {}

    def sink(res):
        write_json_atomic(runs_dir / f"{res['key']}.json", res)
        (study_dir / "failed" / f"{res['key']}.json").unlink(missing_ok=True)
        done[res["key"]] = res
        bar.update(1)
        bar.set_postfix_str(res["key"])

    def fail(spec, reason):
        write_json_atomic(study_dir / "failed" / f"{spec['key']}.json", {"key": spec["key"], "spec": spec,
                                                                          "reason": reason})
        failed[spec["key"]] = reason
        bar.write(f"run {spec['key']} failed: {reason}")

    try:
        if todo:
            if executor == "local":
                _run_local(todo, workers, sink, fail, time_limit)
            elif executor == "ray":
                _run_ray(todo, workers, address, sink, fail, time_limit)
            else:
                raise ValueError("executor must be 'local' or 'ray'")
    finally:
        bar.close()
    elapsed = time.perf_counter() - t0
    results = [done[s["key"]] for s in specs if s["key"] in done]
    complete = len(results) == len(specs)
    meta_path = study_dir / "study.json"
    prev = json.loads(meta_path.read_text()) if meta_path.exists() else {}
    if not same_spec(prev.get("plan"), plan):  # another scale or setting in this directory: its sessions are not ours
        prev = {}
    meta = {
        "study": name, "plan": plan, "seeds": plan["seeds"], "runs_total": len(specs), "runs_done": len(results),
        "complete": complete, "executor": executor, "workers": workers,
        "versions": versions(), "commit": git_commit(),
        "sessions": prev.get("sessions", []) + [{"ran": len(todo), "wall_s": round(elapsed, 1), "executor": executor,
                                                 "workers": workers, "time_limit_s": time_limit,
                                                 "failed": failed}],
        "run_wall_s_total": round(sum(r.get("wall_s", 0.0) for r in results), 1),
        "code_digests": sorted({r["code"] for r in results if r.get("code")}),
    }
    meta["wall_s_total"] = round(sum(s["wall_s"] for s in meta["sessions"]), 1)
    write_json_atomic(meta_path, meta)
    summary = {"study_dir": str(study_dir), "complete": complete, "runs": len(results), "total": len(specs),
               "wall_s": elapsed, "failed": failed}
    from .report import distinct_check

    summary["duplicates"] = distinct_check(results)[1]
    if summary["duplicates"]:
        print(f"ERROR: the same run appears twice in a row of the table: {summary['duplicates']}", file=sys.stderr)
    if report and results:
        summary["table"] = write_report(name, study_dir, plan, results, meta)
    return summary


def build_parser(parser: argparse.ArgumentParser | None = None) -> argparse.ArgumentParser:
    p = parser or OneLineParser(prog="cogmap reproduce", description="Reproduce a study of the paper")
    p.add_argument("study", choices=studies())
    p.add_argument("--out", default="results", help="output directory (default: results/)")
    p.add_argument("--scale", default="reduced", choices=("reduced", "full", "tiny"))
    p.add_argument("--workers", type=positive_int, default=1, help="parallel runs (default: 1)")
    p.add_argument("--executor", default="local", choices=("local", "ray"))
    p.add_argument("--address", default=None, help="Ray cluster address (default: start a local Ray)")
    p.add_argument("--seeds", type=seed_int, nargs="+", default=None, metavar="SEED",
                   help="run only these seeds (integers 0 .. MAX_SEED; default: the study's)")
    p.add_argument("--envs", nargs="*", default=None)
    p.add_argument("--methods", nargs="*", default=None)
    p.add_argument("--limit", type=positive_int, default=None, help="run at most this many missing runs")
    p.add_argument("--time-limit", type=positive_float, default=1800.0,
                   help="wall-clock seconds per run before it is stopped and recorded as failed "
                        "(default: 1800)")
    p.add_argument("--quiet", action="store_true")
    return p


def run_from_args(args) -> int:
    summary = run_study(args.study, args.out, seeds=args.seeds, envs=args.envs, methods=args.methods,
                        scale=args.scale, workers=args.workers, executor=args.executor, address=args.address,
                        limit=args.limit, progress=not args.quiet,
                        time_limit=args.time_limit)
    if summary.get("table"):
        print(summary["table"])
    print(f"{summary['runs']}/{summary['total']} runs in {summary['study_dir']} "
          f"({summary['wall_s']:.0f} s this session)")
    if summary["failed"]:
        print(f"{len(summary['failed'])} runs failed (reasons in failed/*.json; a new session retries them)")
    if summary["duplicates"]:
        return 4
    return 0 if summary["complete"] else 3

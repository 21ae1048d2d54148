"""Worker processes with a wall-clock limit per run.

``workers`` long-lived child processes (spawned: pybullet and jax do not like fork) take run
specs from a task queue and report each result. The parent watches how long every worker has
been on its current run: past ``time_limit`` seconds the worker is killed (a hung native call,
such as a renderer that never returns, cannot be interrupted from inside), the run is reported as
failed with the reason, and a fresh worker takes its place. A worker that dies on its own is
reported the same way. Nothing else waits on a stuck run, so a study always finishes. Workers
ignore Ctrl-C; the parent stops them all on any exit, Ctrl-C included (finished runs are already
written). A worker also ends when its parent dies without stopping it (SIGKILL, a crash): the
kernel sends it SIGKILL (Linux ``PR_SET_PDEATHSIG``), and a watchdog thread that sees its parent
change ends it within :data:`WATCH_S` seconds on any system.
"""

from __future__ import annotations

import multiprocessing as mp
import os
import queue as queue_mod
import signal
import threading
import time
import traceback
from collections.abc import Callable

POLL_S = 0.1
#: how often a worker checks that its parent is alive, seconds
WATCH_S = 0.5
_PR_SET_PDEATHSIG = 1  # linux/prctl.h


def _die_with_parent(parent: int) -> None:
    """End this process when ``parent`` (the process that started it) ends, however it ends."""
    try:
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)
    except (OSError, AttributeError):  # not Linux: the watchdog below does it
        pass
    if os.getppid() != parent:  # the parent died before the request above
        os._exit(1)

    def watch():
        while os.getppid() == parent:
            time.sleep(WATCH_S)
        os._exit(1)

    threading.Thread(target=watch, name="parent-watchdog", daemon=True).start()


def _worker(fn, tasks, results, parent: int) -> None:
    _die_with_parent(parent)
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's to handle: it stops the workers
    while True:
        item = tasks.get()
        if item is None:
            return
        index, spec = item
        results.put(("start", index, os.getpid()))
        try:
            results.put(("done", index, fn(spec)))
        except Exception as err:  # the run fails; the worker goes on with the next one
            line = traceback.format_exception_only(type(err), err)[-1].strip()
            results.put(("error", index, line))


def run_supervised(fn: Callable[[dict], dict], specs: list[dict], workers: int, time_limit: float | None,
                   sink: Callable[[dict], None], fail: Callable[[dict, str], None]) -> None:
    """Run ``fn(spec)`` for every spec in ``workers`` processes; ``sink(result)`` for each finished
    run, ``fail(spec, reason)`` for one that raised, died or exceeded ``time_limit`` seconds."""
    ctx = mp.get_context("spawn")
    tasks, results = ctx.Queue(), ctx.Queue()
    for item in enumerate(specs):
        tasks.put(item)
    procs: list = []

    def spawn():
        p = ctx.Process(target=_worker, args=(fn, tasks, results, os.getpid()), daemon=True)
        p.start()
        procs.append(p)
        return p

    for _ in range(max(1, min(workers, len(specs)))):
        spawn()
    started: dict[int, float] = {}  # run index -> start time (monotonic)
    owner: dict[int, int] = {}  # run index -> pid of the worker running it
    finished = 0
    try:
        while finished < len(specs):
            try:
                kind, index, payload = results.get(timeout=POLL_S)
            except queue_mod.Empty:
                kind = None
            if kind == "start":
                started[index], owner[index] = time.monotonic(), payload
            elif kind in ("done", "error"):
                started.pop(index, None)
                owner.pop(index, None)
                finished += 1
                if kind == "done":
                    sink(payload)
                else:
                    fail(specs[index], payload)
            now = time.monotonic()
            for index, t0 in list(started.items()):
                proc = next((p for p in procs if p.pid == owner[index]), None)
                over = time_limit is not None and now - t0 > time_limit
                dead = proc is None or not proc.is_alive()  # workers only exit when killed or crashed
                if not (over or dead):
                    continue
                reason = (f"exceeded the time limit of {time_limit:g} s" if over
                          else f"its worker process died (exit code {None if proc is None else proc.exitcode})")
                if proc is not None:
                    proc.kill()
                    proc.join()
                    procs.remove(proc)
                del started[index], owner[index]
                finished += 1
                fail(specs[index], reason)
                if finished + len(started) < len(specs):
                    spawn()
            if finished < len(specs) and not any(p.is_alive() for p in procs):
                spawn()  # never wait on runs with no worker left to take them
    finally:
        if finished == len(specs):  # all idle: let them leave on their own (no lock held when they go)
            for p in procs:
                if p.is_alive():
                    tasks.put(None)
            for p in procs:
                p.join(timeout=2.0)
        for p in procs:
            if p.is_alive():
                p.kill()
            p.join()
        for q in (tasks, results):  # release the queues' pipes and semaphores now, not at exit
            q.cancel_join_thread()
            q.close()


def run_one(fn: Callable[[dict], dict], spec: dict, time_limit: float | None) -> tuple[bool, dict | str]:
    """Run ``fn(spec)`` once in a supervised worker process (the mechanism of :func:`run_supervised`
    with one run): ``(True, result)`` when it finished, ``(False, reason)`` when it raised, died or
    exceeded ``time_limit`` seconds (the worker is then killed). Used by the command line, so that no
    single command can hang."""
    outcome: list = []
    run_supervised(fn, [spec], 1, time_limit, lambda result: outcome.append((True, result)),
                   lambda _spec, reason: outcome.append((False, reason)))
    return outcome[0]

"""Study runs as Ray tasks, with the guarantees of the local executor (:mod:`.supervisor`).

At most as many runs are in flight as there are workers (and CPUs in the cluster), so a run's
time is counted from when it can start. A run past ``time_limit`` seconds is cancelled (its worker
process killed, ``ray.cancel(force=True)``) and reported as failed with the reason; a task that
raised, or whose worker died, is reported with its error in one line; the study goes on with the
next run in every case. Results are the same per seed as with the local executor.
"""

from __future__ import annotations

import time
from collections.abc import Callable

#: how long one wait for a finished task lasts before the time limits are checked, seconds
POLL_S = 0.2

RAY_MISSING = "the ray executor needs Ray, which is not installed; install it with: pip install 'cogmap[ray]'"


def require_ray():
    """The ``ray`` module, or a one-line error saying how to install it.

    Returns
    -------
    module
        ``ray``.

    Raises
    ------
    RuntimeError
        When Ray is not installed (:data:`RAY_MISSING`).
    """
    try:
        import ray
    except ImportError:
        raise RuntimeError(RAY_MISSING) from None
    return ray


def _one_line(err: BaseException) -> str:
    cause = getattr(err, "cause", None)  # a RayTaskError carries the task's own exception
    shown = cause if isinstance(cause, BaseException) else err
    lines = [line for line in str(shown).splitlines() if line.strip()]
    return f"{type(shown).__name__}: {lines[-1] if lines else ''}".strip()


def run_ray(fn: Callable, specs: list, workers: int, address: str | None, time_limit: float | None,
            sink: Callable, fail: Callable) -> None:
    """Run ``fn(spec)`` for every spec as a Ray task; ``sink(result)`` for each finished run,
    ``fail(spec, reason)`` for one that raised, died or exceeded ``time_limit`` seconds.

    Parameters
    ----------
    fn : callable
        The run (importable in the cluster's workers, e.g. :func:`cogmap.study.registry.execute`).
    specs : list
        One spec per run.
    workers : int
        Runs in flight at once (at most the cluster's CPUs).
    address : str or None
        Address of a running cluster (``ray start --head`` prints it); None starts a local Ray
        with ``workers`` CPUs, stopped again at the end.
    time_limit : float or None
        Seconds a run may take; None for no limit.
    sink, fail : callable
        Called in this process for each finished and each failed run.
    """
    ray = require_ray()
    started = False
    if not ray.is_initialized():
        kw = {"include_dashboard": False, "log_to_driver": False, "ignore_reinit_error": True}
        if address:
            ray.init(address=address, **kw)
        else:
            ray.init(num_cpus=max(1, workers), **kw)
        started = True
    try:
        cpus = int(ray.cluster_resources().get("CPU", 1))
        slots = max(1, min(workers, cpus))
        remote = ray.remote(num_cpus=1, max_retries=0)(fn)
        queue = list(enumerate(specs))
        running: dict = {}  # ref -> (spec index, start time)
        while queue or running:
            while queue and len(running) < slots:
                index, spec = queue.pop(0)
                running[remote.remote(spec)] = (index, time.monotonic())
            done, _ = ray.wait(list(running), num_returns=1, timeout=POLL_S)
            for ref in done:
                index, _ = running.pop(ref)
                try:
                    result = ray.get(ref)
                except Exception as err:  # noqa: BLE001 - the run fails, the study goes on
                    fail(specs[index], _one_line(err))
                else:
                    sink(result)
            now = time.monotonic()
            for ref, (index, t0) in list(running.items()):
                if time_limit is not None and now - t0 > time_limit:
                    ray.cancel(ref, force=True)
                    del running[ref]
                    fail(specs[index], f"exceeded the time limit of {time_limit:g} s")
    finally:
        if started:
            ray.shutdown()

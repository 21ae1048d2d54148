"""Studies by name, each registered once: its plan, its run specs, one run, its report.

A study (the :class:`cogmap.genmodel.contracts.Study` contract) is four functions::

    plan(scale, seeds=None, methods=None, envs=None) -> dict   # environments, methods, seeds, budgets
    specs(plan) -> [spec]                                       # one JSON-able spec per run, with its key
    run(spec) -> dict                                           # one run's result
    report(study_dir, plan, results) -> str                     # tables and figures; the markdown body

:func:`register_study` adds one (checked against the contract); ``cogmap reproduce NAME``,
:func:`study_plan`, :func:`run_specs`, :func:`execute` and :func:`write_report` find it by name.
The built-in studies are registered at the end of this module.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from functools import partial
from pathlib import Path
from typing import NamedTuple

from cogmap.genmodel.contracts import Study
from cogmap.genmodel.registry import Registry

from . import config, drone, dvbf_exploration, dvbf_navigation, dvbf_slam, recovery, report, runs

SCALES = ("reduced", "full", "tiny")


class StudyEntry(NamedTuple):
    """A registered study (see the module docstring for the four functions).

    Attributes
    ----------
    name : str
        Its registered name.
    plan, specs, run, report : callable
        The study's four functions.
    """

    name: str
    plan: Callable[..., dict]
    specs: Callable[[dict], list]
    run: Callable[[dict], dict]
    report: Callable[..., str]


_STUDIES = Registry("study", "register_study", protocol=Study, missing=ValueError)


def register_study(name: str, *, plan, specs, run, report, overwrite: bool = False) -> StudyEntry:
    """Register a study under ``name``.

    Parameters
    ----------
    name : str
        The name ``cogmap reproduce NAME`` and ``run_study(NAME)`` use; the specs' ``"study"``.
    plan, specs, run, report : callable
        The study's four functions (module docstring).
    overwrite : bool, optional
        Replace a study registered under ``name`` (built-in studies cannot be replaced).

    Returns
    -------
    StudyEntry

    Raises
    ------
    ValueError
        Empty name, a built-in name, or a taken name without ``overwrite``.
    TypeError
        A function missing or not callable as the contract says.
    """
    return _STUDIES.add(name, StudyEntry(name, plan, specs, run, report), overwrite)


#: the study registered under a name (``ValueError`` listing the studies for an unknown one)
get_study = _STUDIES.get
#: names of the registered studies, in registration order
studies = _STUDIES.names
#: remove a study added with :func:`register_study` (built-in ones stay)
unregister_study = _STUDIES.remove


def study_plan(study: str, scale: str = "reduced", envs=None, seeds=None, methods=None) -> dict:
    """Environments, methods, seeds and parameters of ``study`` at ``scale``.

    Parameters
    ----------
    study : str
        A registered study.
    scale : str, optional
        ``"reduced"`` (default), ``"full"`` or ``"tiny"``.
    envs, seeds, methods : sequence, optional
        Restrict the study's environments, seeds and methods.

    Returns
    -------
    dict
        The plan: ``study``, ``scale``, ``envs``, ``methods``, ``seeds``, ``steps``, ``params``, ...

    Raises
    ------
    ValueError
        For an unknown study or scale, or restrictions the study refuses.
    """
    entry = get_study(study)
    if scale not in SCALES:
        raise ValueError("scale must be 'reduced', 'full' or 'tiny'")
    return entry.plan(scale, seeds=seeds, methods=methods, envs=envs)


def run_specs(plan: dict) -> list[dict]:
    """One JSON-able spec per run of ``plan`` (each with its key: readable names plus a digest of
    everything that changes the run, so a changed setting never reuses an old run).

    Parameters
    ----------
    plan : dict
        From :func:`study_plan`.

    Returns
    -------
    list of dict
        One spec per run, each with its ``key``.
    """
    return get_study(plan["study"]).specs(plan)


def execute(spec: dict) -> dict:
    """Run one spec and return ``{"spec": spec, "result": ..., "wall_s": ..., "code": digest}`` (JSON-able)."""
    code = runs.code_digest()  # before the run: the code this process imported
    t0 = time.perf_counter()
    result = get_study(spec["study"]).run(spec)
    return runs.clean_json({"key": spec["key"], "spec": spec, "result": result,
                            "wall_s": time.perf_counter() - t0, "code": code})


def code_versions(results, code: str) -> str:
    """``digest: method (runs), ...`` for the runs made with one version of the code."""
    counts: dict[str, int] = {}
    for r in results:
        if r.get("code") == code:
            m = r.get("spec", {}).get("method", "?")
            counts[m] = counts.get(m, 0) + 1
    return f"`{code}` " + ", ".join(f"{m} ({n} runs)" for m, n in sorted(counts.items()))


def write_report(name: str, study_dir: Path, plan, results, meta) -> str:
    """Write ``study_dir/table.md``: a header (runs, commit, wall clock, code versions) and the
    study's report body; return the text."""
    study_dir = Path(study_dir)
    body = get_study(name).report(study_dir, plan, results)
    head = (f"# Study `{name}` ({plan['scale']} scale)\n\n"
            f"{meta['runs_done']}/{meta['runs_total']} runs, commit `{meta['commit']}`, "
            f"wall clock {meta['wall_s_total']:.0f} s over {len(meta['sessions'])} session(s) "
            f"(sum of run times {meta['run_wall_s_total']:.0f} s).\n\n")
    codes = sorted({r.get("code") for r in results if r.get("code")})
    if len(codes) > 1:
        head += (f"**Note:** the runs were made with {len(codes)} versions of the code: "
                 + "; ".join(code_versions(results, c) for c in codes)
                 + ". A run is made again when its settings (its key) change, not when code it may not use "
                 "does.\n\n")
    text = head + body + "\n"
    (study_dir / "table.md").write_text(text)
    return text


def _room(study: str, run, body) -> None:
    register_study(study, plan=partial(config.room_plan, study), specs=config.room_specs, run=run, report=body)


for _name, _run, _report in (
        ("exploration", runs.run_exploration, report.exploration_report),
        ("generalisation", runs.run_exploration, report.generalisation_report),
        ("success", runs.run_exploration, report.success_report),
        ("goals", runs.run_goals, report.goals_report),
        ("drift", runs.run_drift, report.drift_report),
        ("slip", runs.run_drift, report.drift_report),
        ("dropout", runs.run_drift, report.dropout_report),
        ("obstacle", runs.run_obstacle, report.obstacle_report),
        ("scaling", runs.run_scaling, report.scaling_report)):
    _room(_name, _run, _report)
register_study("drone", plan=drone.drone_plan, specs=drone.drone_specs, run=drone.run_drone,
               report=drone.drone_report)
register_study("dvbf-navigation", plan=dvbf_navigation.nav_plan, specs=dvbf_navigation.nav_specs,
               run=dvbf_navigation.run_navigation, report=dvbf_navigation.nav_report)
register_study("dvbf-exploration", plan=dvbf_exploration.dvbf_exploration_plan,
               specs=dvbf_exploration.dvbf_exploration_specs, run=dvbf_exploration.run_dvbf_exploration,
               report=dvbf_exploration.dvbf_exploration_report)
register_study("dvbf-slam", plan=dvbf_slam.dvbf_slam_plan, specs=dvbf_slam.dvbf_slam_specs,
               run=dvbf_slam.run_dvbf_slam, report=dvbf_slam.dvbf_slam_report)
register_study("recovery", plan=recovery.recovery_plan, specs=recovery.recovery_specs,
               run=recovery.run_recovery, report=recovery.recovery_report)
_STUDIES.seal()

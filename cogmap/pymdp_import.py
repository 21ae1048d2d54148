"""A pymdp 1.0 ``Agent`` as a cogmap model and agent loop (the inverse of
:func:`cogmap.inference.to_pymdp`).

    imported = from_pymdp(agent)
    state = loop.init(compile(imported.spec), **imported.settings)
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np


class PymdpImport(NamedTuple):
    """A pymdp ``Agent`` as cogmap sees it (:func:`from_pymdp`).

    Attributes
    ----------
    spec : ModelSpec
        The generative model (``A``, ``B``, ``C``, ``D``, ``pA``, ``pB``); compile it with
        :func:`cogmap.genmodel.compile`.
    settings : dict
        Keyword arguments of :func:`cogmap.loop.init` that reproduce the agent's inference,
        planning and action selection (``scheme``, ``num_iter``, ``policy_len``, ``gamma``,
        ``objective``, ``E``, ``alpha``, ``sampling``, ``sample``, ``learn_A``, ``learn_B``).
    """

    spec: object
    settings: dict


_SCHEMES = {"fpi": "fpi", "vmp": "vmp_pymdp", "mmp": "mmp"}
_SAMPLING = {"full": "policy", "marginal": "marginal"}


def _one(x, index: int, what: str) -> np.ndarray:
    arr = np.asarray(x, dtype=float)
    if arr.ndim < 1 or index >= arr.shape[0]:
        raise ValueError(f"from_pymdp: {what} has no batch entry {index} (shape {arr.shape})")
    out = arr[index]
    if not np.all(np.isfinite(out)):
        raise ValueError(f"from_pymdp: {what} has non-finite entries")
    return out


def from_pymdp(agent, index: int = 0) -> PymdpImport:
    """The model and loop settings of a pymdp 1.0 ``Agent`` (the inverse of :func:`to_pymdp`).

    ``A``, ``B``, ``C``, ``D``, ``E``, ``A_dependencies``, ``B_dependencies`` (as
    ``Factor.depends_on``), ``pA``, ``pB`` and the settings that
    have a cogmap equivalent are carried over: ``inference_algo`` (``"fpi"``; ``"vmp"`` becomes
    ``vmp_pymdp``, pymdp's schedule; ``"mmp"``), ``num_iter``, ``policy_len``, ``gamma``,
    ``alpha``, ``action_selection`` (``"stochastic"``: ``sample=True``), ``sampling_mode``
    (``"full"``: ``sampling="policy"``; ``"marginal"``), ``use_utility`` /
    ``use_states_info_gain`` / ``use_param_info_gain`` (the objective) and ``learn_A`` /
    ``learn_B``. Factors are named ``factor_0 ...``, modalities ``modality_0 ...``.

    Parameters
    ----------
    agent : pymdp.agent.Agent
        A pymdp 1.0 agent.
    index : int, optional
        Which agent of a batch to take, default 0.

    Returns
    -------
    PymdpImport
        ``spec`` and ``settings``: ``loop.init(compile(spec), **settings)`` is the same agent.

    Raises
    ------
    ValueError
        For what cogmap cannot express yet, naming it: transitions that depend on several
        control factors (``B_action_dependencies``), learning ``B`` when transitions depend on
        other factors, custom policies, the inductive term, learning
        of ``C``, ``D`` or ``E``, an unknown inference algorithm; or a batch entry that is not there.
    """
    from cogmap.genmodel.spec import Factor, Modality, ModelSpec
    from cogmap.planning import efe
    from cogmap.planning.policies import enumerate_policies

    if not isinstance(index, int | np.integer) or index < 0:
        raise ValueError(f"from_pymdp: index must be a non-negative integer, got {index!r}")
    F, M = len(agent.B), len(agent.A)
    b_deps = [[int(x) for x in d] for d in (agent.B_dependencies or [[f] for f in range(F)])]
    multi = any(d != [f] for f, d in enumerate(b_deps))
    if multi and agent.learn_B:
        raise ValueError(f"from_pymdp: learning B (learn_B) with transitions that depend on other factors "
                         f"(B_dependencies {b_deps}) is not supported yet")
    act_deps = getattr(agent, "B_action_dependencies", None)
    if act_deps is not None and [list(d) for d in act_deps] != [[f] for f in range(F)]:
        raise ValueError(f"from_pymdp: B_action_dependencies {act_deps} (controls acting on several factors) "
                         "are not supported yet")
    if agent.use_inductive:
        raise ValueError("from_pymdp: the inductive term (use_inductive) is not carried over")
    for name in ("learn_C", "learn_D", "learn_E"):
        if getattr(agent, name, False):
            raise ValueError(f"from_pymdp: {name} has no cogmap equivalent yet")
    if agent.inference_algo not in _SCHEMES:
        raise ValueError(f"from_pymdp: inference_algo {agent.inference_algo!r} has no cogmap equivalent "
                         f"(known: {', '.join(_SCHEMES)})")
    if agent.sampling_mode not in _SAMPLING or agent.action_selection not in ("deterministic", "stochastic"):
        raise ValueError(f"from_pymdp: action_selection {agent.action_selection!r} / sampling_mode "
                         f"{agent.sampling_mode!r} not understood")
    num_controls = [int(u) for u in agent.num_controls]
    policies = np.asarray(agent.policies.policy_arr)
    ours = enumerate_policies(num_controls, int(agent.policy_len))
    if policies.shape != ours.shape or not np.array_equal(policies, ours):
        raise ValueError("from_pymdp: the agent's policies are not the enumeration of every policy of "
                         f"policy_len {agent.policy_len} (custom policies are not carried over)")
    A = [_one(a, index, f"A[{m}]") for m, a in enumerate(agent.A)]
    B = [_one(b, index, f"B[{f}]") for f, b in enumerate(agent.B)]
    factors = [Factor(f"factor_{f}", B[f].shape[0], num_controls=num_controls[f],
                      depends_on=None if b_deps[f] == [f] else tuple(f"factor_{d}" for d in b_deps[f]))
               for f in range(F)]
    a_deps = [list(d) for d in agent.A_dependencies]
    modalities = [Modality(f"modality_{m}", A[m].shape[0], tuple(f"factor_{f}" for f in a_deps[m]))
                  for m in range(M)]
    spec = ModelSpec(
        factors=factors, modalities=modalities,
        A={mod.name: A[m] for m, mod in enumerate(modalities)},
        B={fac.name: B[f] for f, fac in enumerate(factors)},
        C={mod.name: _one(agent.C[m], index, f"C[{m}]") for m, mod in enumerate(modalities)},
        D={fac.name: _one(agent.D[f], index, f"D[{f}]") for f, fac in enumerate(factors)},
        pA={} if agent.pA is None else {mod.name: _one(agent.pA[m], index, f"pA[{m}]")
                                         for m, mod in enumerate(modalities)},
        pB={} if agent.pB is None else {fac.name: _one(agent.pB[f], index, f"pB[{f}]")
                                         for f, fac in enumerate(factors)},
    )
    settings = dict(
        scheme=_SCHEMES[agent.inference_algo], num_iter=int(agent.num_iter), policy_len=int(agent.policy_len),
        gamma=float(_one(np.reshape(agent.gamma, (-1,)), index, "gamma")),
        alpha=float(_one(np.reshape(agent.alpha, (-1,)), index, "alpha")),
        objective=efe.pymdp_like(bool(agent.use_utility), bool(agent.use_states_info_gain),
                                 bool(agent.use_param_info_gain)),
        E=_one(agent.E, index, "E"), sampling=_SAMPLING[agent.sampling_mode],
        sample=agent.action_selection == "stochastic", learn_A=bool(agent.learn_A), learn_B=bool(agent.learn_B),
    )
    return PymdpImport(spec, settings)


__all__ = ["PymdpImport", "from_pymdp"]

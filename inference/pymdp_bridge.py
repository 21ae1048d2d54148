"""Build a pymdp 1.0 ``Agent`` from a compiled model (references, benchmarks, comparisons); the
other direction, a cogmap model and loop from a pymdp ``Agent``, is :func:`cogmap.pymdp_import.from_pymdp`."""

from __future__ import annotations

import numpy as np


def to_pymdp(model, **agent_kwargs):
    """A pymdp 1.0 ``Agent`` holding the live slices of ``model`` with a batch axis of 1.

    ``A``, ``B`` (dense, also from sparse storage), ``C``, ``D``, ``A_dependencies``,
    ``B_dependencies`` (``model.B_deps``) and, when
    present for every modality/factor, ``pA`` / ``pB`` are passed. Arrays use JAX's default float
    type (enable ``jax_enable_x64`` for double precision). Requires the ``pymdp`` extra.

    Parameters
    ----------
    model : Model
        Compiled model.
    **agent_kwargs
        Passed to ``Agent`` unchanged (for example ``inference_algo="mmp"``, ``num_iter=16``).

    Returns
    -------
    pymdp.agent.Agent

    Raises
    ------
    ImportError
        If pymdp 1.0 is not installed.
    """
    try:
        import jax.numpy as jnp
        from pymdp.agent import Agent
    except ImportError as err:  # pragma: no cover - depends on the environment
        raise ImportError(
            "to_pymdp needs pymdp 1.0: pip install 'cogmap[pymdp]' "
            "(PyPI name inferactively-pymdp)"
        ) from err

    def batched(x):
        return jnp.asarray(np.asarray(x, dtype=float))[None]

    M = len(model.modalities)
    F = len(model.factors)
    A = [batched(model.live_A(m)) for m in range(M)]
    B = [batched(model.live_B(f)) for f in range(F)]
    C = [batched(model.live_C(m)) for m in range(M)]
    D = [batched(model.live_D(f)) for f in range(F)]
    kwargs = dict(
        A_dependencies=[list(d) for d in model.A_deps],
        B_dependencies=[list(d) for d in getattr(model, "B_deps", None) or [[f] for f in range(F)]],
        num_controls=list(model.num_controls),
    )
    pA = [model.live_pA(m) for m in range(M)]
    if all(p is not None for p in pA):
        kwargs["pA"] = [batched(p) for p in pA]
    pB = [model.live_pB(f) for f in range(F)]
    if all(p is not None for p in pB):
        kwargs["pB"] = [batched(p) for p in pB]
    kwargs.update(agent_kwargs)
    return Agent(A, B, C, D, **kwargs)


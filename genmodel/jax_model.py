"""A compiled model's dense arrays as a JAX pytree, at the model's capacity with masks of live states.

    layout, arrays = to_jax(model)       # static structure + a pytree of arrays
    jax.vmap(fn, in_axes=(None, 0))(layout, stacked_arrays)   # a batch of models or parameters

:class:`Layout` is the static part (dependencies, controls, sizes): hashable, closed over by
``jax.jit``. :class:`JaxModel` holds every array, so it can be batched (``jax.vmap``), differentiated
(``jax.grad``) and replaced field by field (``arrays._replace(C=...)``). Arrays keep the model's
capacity: a growing model exported again has the same shapes until a capacity doubles, so
compiled functions are reused; entries of not-yet-live states and outcomes are zero and the
``live`` masks keep every belief at exactly zero there. Only dense transitions can be exported
(sparse maps stay on the numpy path). Precision follows JAX: enable float64
(``jax.config.update("jax_enable_x64", True)`` or ``with jax.enable_x64(True):``) to agree with the
numpy backend to 1e-10.
"""

from __future__ import annotations

from typing import NamedTuple

import jax.numpy as jnp
import numpy as np

from .spec import SpecError


class Layout(NamedTuple):
    """The static structure of a model on the JAX backend (hashable; part of a jit cache key).

    Attributes
    ----------
    A_deps : tuple of tuple of int
        Factors each modality depends on.
    num_controls : tuple of int
        Controls per factor.
    capacity : tuple of int
        Array size (states, live or reserved) per factor.
    obs_capacity : tuple of int
        Array size (outcomes) per modality.
    goal_factor : int
        Factor of the goal states of the inductive term.
    inductive_depth : int
        Horizon of the inductive term (steps).
    """

    A_deps: tuple
    num_controls: tuple
    capacity: tuple
    obs_capacity: tuple
    goal_factor: int = 0
    inductive_depth: int = 10

    @property
    def num_factors(self) -> int:
        """Number of hidden-state factors."""
        return len(self.capacity)

    @property
    def num_modalities(self) -> int:
        """Number of observation modalities."""
        return len(self.obs_capacity)


class JaxModel(NamedTuple):
    """Every array of a dense model (a pytree: batch it, differentiate it, replace fields).

    Attributes
    ----------
    A : tuple of jax.Array
        Per modality ``(obs_capacity[m], *capacity[deps])`` float likelihood.
    B : tuple of jax.Array
        Per factor ``(capacity[f], capacity[f], num_controls[f])`` float transitions.
    C : tuple of jax.Array
        Per modality ``(obs_capacity[m],)`` float log-preferences over outcomes.
    D : tuple of jax.Array
        Per factor ``(capacity[f],)`` float initial belief.
    C_states : tuple of jax.Array
        Per factor ``(capacity[f],)`` float log-preferences over states.
    pA : tuple
        Per modality the Dirichlet counts of ``A`` (shaped as ``A``) or None.
    pB : tuple
        Per factor the Dirichlet counts of ``B`` (shaped as ``B``) or None.
    live : tuple of jax.Array
        Per factor ``(capacity[f],)`` bool mask of live states.
    goal_dist : jax.Array or None
        ``(capacity[goal_factor],)`` float steps to the nearest goal state (``inf`` beyond the
        inductive horizon), or None without a goal.
    """

    A: tuple
    B: tuple
    C: tuple
    D: tuple
    C_states: tuple
    pA: tuple
    pB: tuple
    live: tuple
    goal_dist: object = None


def _live_block(x: np.ndarray, sizes: tuple) -> np.ndarray:
    """``x`` with every entry outside the leading live block ``sizes`` set to zero."""
    out = np.zeros_like(x)
    idx = tuple(slice(0, n) for n in sizes)
    out[idx] = x[idx]
    return out


def to_jax(model, *, goal_dist=None, goal_factor: int = 0, inductive_depth: int | None = None,
           dtype=None) -> tuple[Layout, JaxModel]:
    """The static layout and the arrays of a compiled dense model for the JAX backend.

    Parameters
    ----------
    model : Model
        A compiled model (:func:`cogmap.genmodel.compile`) whose transitions are all dense.
    goal_dist : array_like, optional
        ``(capacity[goal_factor],)`` float steps to the nearest goal state (``inf`` beyond the
        horizon) for the inductive term; :func:`cogmap.planning.jax_efe.goal_distances_of` computes
        it as the numpy planner does. Default None: no goal.
    goal_factor : int, optional
        Factor of the goal states, default 0.
    inductive_depth : int, optional
        Horizon of the inductive term; default the model's (10 without an inductive spec).
    dtype : numpy dtype, optional
        Float type of the arrays; default JAX's (float64 when x64 is enabled, else float32).

    Returns
    -------
    layout : Layout
    arrays : JaxModel

    Raises
    ------
    SpecError
        If a factor has sparse transitions (the numpy backend is the path for sparse maps), or
        transitions that depend on several factors (``B_dependencies``: numpy backend only, for now).
    """
    refuse = getattr(model, "refuse_B_deps", None)
    if refuse is not None:
        refuse("the JAX backend (to_jax)")
    sparse = [f.name for i, f in enumerate(model.factors) if model.is_sparse(i)]
    if sparse:
        raise SpecError(f"the JAX backend needs dense transitions; factor(s) {', '.join(sparse)} are sparse "
                        "(use the numpy backend for sparse maps)")
    F, M = len(model.factors), len(model.modalities)
    caps = tuple(int(model.B[f].prob.shape[0]) for f in range(F))
    ocaps = tuple(int(model.A[m].prob.shape[0]) for m in range(M))
    n, o = tuple(model.num_states), tuple(model.num_obs)
    deps = tuple(tuple(int(f) for f in d) for d in model.A_deps)
    as_j = (lambda x: jnp.asarray(x)) if dtype is None else (lambda x: jnp.asarray(x, dtype=dtype))

    def a_block(x, m):
        return as_j(_live_block(np.asarray(x, dtype=float), (o[m],) + tuple(n[f] for f in deps[m])))

    def b_block(x, f):
        return as_j(_live_block(np.asarray(x, dtype=float), (n[f], n[f])))

    A = tuple(a_block(model.A[m].prob, m) for m in range(M))
    pA = tuple(None if model.A[m].counts is None else a_block(model.A[m].counts, m) for m in range(M))
    B = tuple(b_block(model.B[f].prob, f) for f in range(F))
    pB = tuple(None if model.B[f].counts is None else b_block(model.B[f].counts, f) for f in range(F))
    C = tuple(as_j(_live_block(np.asarray(model.C[m], dtype=float), (o[m],))) for m in range(M))
    D = tuple(as_j(_live_block(np.asarray(model.D[f], dtype=float), (n[f],))) for f in range(F))
    Cs = tuple(as_j(_live_block(np.asarray(model.C_states[f], dtype=float), (n[f],))) for f in range(F))
    live = tuple(jnp.asarray(np.arange(caps[f]) < n[f]) for f in range(F))
    if goal_dist is not None:
        goal_dist = as_j(np.asarray(goal_dist, dtype=float))
        if goal_dist.shape != (caps[goal_factor],):
            raise SpecError(f"goal_dist must have shape ({caps[goal_factor]},), got {goal_dist.shape}")
    if inductive_depth is None:
        inductive_depth = 10 if model.inductive is None else int(model.inductive.depth)
    ctrl = tuple(int(u) for u in model.num_controls)
    layout = Layout(deps, ctrl, caps, ocaps, int(goal_factor), int(inductive_depth))
    return layout, JaxModel(A, B, C, D, Cs, pA, pB, live, goal_dist)


__all__ = ["JaxModel", "Layout", "to_jax"]

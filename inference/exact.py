"""Exact Bayesian state inference by enumerating the joint (product) state space.

Forward filtering gives the last-step marginals and ``-log p(o_T | o_<T)``; a backward pass
gives smoothed marginals for every step (``info.history``). Cost grows with the product of the
live factor sizes, so the joint size is capped (option ``max_joint``).
"""

from __future__ import annotations

import numpy as np

from .base import InferenceError, InferenceInfo, dense_transition, prepare, transition_array

MAX_JOINT = 1 << 16


def _apply(B: np.ndarray, x: np.ndarray, axis: int, transpose: bool = False) -> np.ndarray:
    """Apply a ``(next, current)`` matrix along ``axis`` of the joint tensor ``x``."""
    y = np.tensordot(B, x, axes=([0 if transpose else 1], [axis]))
    return np.moveaxis(y, 0, axis)


_PREV = "abcdefghijklm"
_NEXT = "nopqrstuvwxyz"


def _dependent_step(model, action, F: int):
    """The joint transition of one step as einsum operands: per factor ``B_f[..., u_f]`` with its
    subscripts (next state of ``f``, previous states of its dependencies)."""
    ops, subs = [], []
    for f, u in enumerate(action):
        ops.append(transition_array(model, f, u))
        subs.append(_NEXT[f] + "".join(_PREV[d] for d in model.B_deps[f]))
    return ops, subs


def _apply_joint(step, x: np.ndarray, F: int, backward: bool = False) -> np.ndarray:
    """``p(s') = sum_s prod_f B_f(s'_f | s_deps_f) x(s)``, or the backward message
    ``b(s) = sum_s' prod_f B_f(s'_f | s_deps_f) x(s')``."""
    ops, subs = step
    prev, nxt = _PREV[:F], _NEXT[:F]
    spec = ",".join(subs) + "," + (nxt if backward else prev) + "->" + (prev if backward else nxt)
    return np.einsum(spec, *ops, x, optimize=True)


def _joint_likelihood(evidence, sizes) -> tuple[np.ndarray, float]:
    lik = np.ones(sizes)
    log_scale = 0.0
    F = len(sizes)
    for ev in evidence:
        shape = [1] * F
        for f, n in zip(ev.deps, ev.lik.shape, strict=True):
            shape[f] = n
        # a factor may appear once per modality; reorder the axes into factor order
        order = np.argsort(ev.deps)
        lik = lik * np.transpose(ev.lik, order).reshape(shape)
        log_scale += ev.log_scale
    return lik, log_scale


def _marginals(joint: np.ndarray) -> tuple[np.ndarray, ...]:
    F = joint.ndim
    return tuple(joint.sum(axis=tuple(g for g in range(F) if g != f)) for f in range(F))


def exact(model, prior, observations, actions=None, *, smooth: bool = True, max_joint: int = MAX_JOINT):
    """Exact Bayes over the joint state space (the prior is taken as a product of factors).

    Transitions that depend on several factors (``model.B_deps``) enter exactly: the joint
    transition is ``prod_f B_f(s'_f | s_deps_f, u_f)``.

    Parameters
    ----------
    model, prior, observations, actions
        The arguments every scheme takes (:class:`cogmap.genmodel.contracts.InferenceScheme`), checked
        and documented by :func:`cogmap.inference.base.prepare`.
    smooth : bool, optional
        Whether ``info.history`` holds smoothed (forward-backward) marginals (default) or filtered ones.
    max_joint : int, optional
        Largest joint state space accepted.

    Returns
    -------
    posterior : list of numpy.ndarray
        ``(num_states[f],)`` float belief per factor at the last step, each summing to 1.
    info : InferenceInfo
        ``free_energy`` is ``-log p(o_T | o_<T)``, ``total_free_energy`` ``-log p(o_1:T)``;
        ``history`` holds per-step marginals of every factor.

    Raises
    ------
    InferenceError
        When the joint has more than ``max_joint`` states, the inputs are invalid, or the
        observations have zero probability under the model.
    """
    prob = prepare(model, prior, observations, actions)
    sizes = prob.sizes
    joint_size = int(np.prod(sizes))
    if joint_size > max_joint:
        raise InferenceError(
            f"exact: the joint state space has {joint_size} states (sizes {list(sizes)}), above "
            f"max_joint={max_joint}; use a variational scheme or raise max_joint"
        )
    F = len(sizes)
    multi = getattr(model, "has_B_deps", False)
    if multi and F > len(_PREV):
        raise InferenceError(f"exact: transitions that depend on several factors are supported for up to "
                             f"{len(_PREV)} factors, the model has {F}")
    alpha = prob.prior[0]
    for f in range(1, F):
        alpha = np.multiply.outer(alpha, prob.prior[f])
    alpha = alpha.reshape(sizes)
    alphas, liks, mats = [], [], []
    log_c = []
    for t in range(prob.T):
        if t > 0 and multi:  # joint transition: product over factors of B_f given its dependencies
            step = _dependent_step(model, prob.actions[t - 1], F)
            mats.append(step)
            alpha = _apply_joint(step, alpha, F)
        elif t > 0:
            step = [dense_transition(model, f, u) for f, u in enumerate(prob.actions[t - 1])]
            mats.append(step)
            for f in range(F):
                alpha = _apply(step[f], alpha, f)
        lik, scale = _joint_likelihood(prob.evidence[t], sizes)
        post = alpha * lik
        c = post.sum()
        if c > 0 and np.isfinite(c):
            log_c_t = float(np.log(c))
        else:  # the product underflowed: redo it in log space
            with np.errstate(divide="ignore"):
                log_post = np.log(alpha) + np.log(lik)
            top = log_post.max()
            if not np.isfinite(top):
                raise InferenceError(
                    f"exact: observations up to step {t} have zero probability under the model"
                )
            post = np.exp(log_post - top)
            c = post.sum()
            log_c_t = float(top + np.log(c))
        alpha = post / c
        log_c.append(log_c_t + scale)
        alphas.append(alpha)
        liks.append(lik)
    if smooth:
        beta = np.ones(sizes)
        gammas = [alphas[-1]]
        for t in range(prob.T - 2, -1, -1):
            x = liks[t + 1] * beta
            if multi:
                x = _apply_joint(mats[t], x, F, backward=True)
            for f in range(F if not multi else 0):
                x = _apply(mats[t][f], x, f, transpose=True)
            beta = x / x.max()  # only the shape of beta matters
            g = alphas[t] * beta
            gammas.append(g / g.sum())
        gammas.reverse()
    else:
        gammas = alphas
    history = tuple(_marginals(g) for g in gammas)
    posterior = list(_marginals(alphas[-1]))
    info = InferenceInfo(float(-log_c[-1]), history, 1, float(-np.sum(log_c)))
    return posterior, info

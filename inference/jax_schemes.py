"""The discrete inference schemes as pure JAX functions (jit, vmap and grad through them).

Each one-step scheme has the call

    qs, free_energy = SCHEMES[name](layout, arrays, prior, evidence, **options)

on the arrays of :func:`cogmap.genmodel.jax_model.to_jax`, with ``prior`` one ``(capacity[f],)``
belief per factor and ``evidence`` from :func:`evidence` (one observation vector per modality:
one-hot for an outcome, a distribution for a soft observation, all zeros when the modality did
not report). They are the numpy schemes of this package (``exact``, ``filter``, ``fpi``,
``vmp``, ``vmp_pymdp``, ``mmp``) written as array programs, with the same update schedules, the
same log floor and the same free energies; the tests hold them to the numpy results within 1e-10
in float64.
The numpy schemes stay the reference: they check their inputs, refuse observations of zero
probability and run on sparse growing maps, which these functions do not (a jitted function
cannot raise on values).

:func:`window` runs ``vmp`` (coordinate ascent on the mean-field free energy,
:func:`mean_field_window`), ``vmp_pymdp`` or ``mmp`` (pymdp 1.0's simultaneous updates) over a
whole sequence at once, as the numpy schemes do with ``window=None``.
"""

from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from cogmap.genmodel.compile import real_array
from cogmap.genmodel.numerics import LOG_FLOOR
from cogmap.genmodel.numerics import floor_log_jax as floor_log


class Evidence(NamedTuple):
    """The likelihood of one time step's observations, per modality.

    Attributes
    ----------
    lik : tuple of jax.Array
        Per modality ``sum_o p(o) A[o, ...]`` over the states of its factors (``*capacity[deps]``).
    present : jax.Array
        ``(M,)`` bool: whether the modality reported.
    """

    lik: tuple
    present: jax.Array


def xlogx_sum(q):
    """``sum q ln q`` over the positive entries (exact, differentiable)."""
    pos = q > 0
    return jnp.sum(jnp.where(pos, q * jnp.log(jnp.where(pos, q, 1.0)), 0.0))


def masked_softmax(x, live):
    """Softmax over the live entries; exactly zero elsewhere."""
    z = jnp.where(live, x, -jnp.inf)
    e = jnp.exp(z - jnp.max(z))
    return e / jnp.sum(e)


def one_hot_observation(layout, observation) -> tuple:
    """Observation vectors from an observation as the numpy schemes take it (host side, not jitted).

    Parameters
    ----------
    layout : Layout
        The model's layout.
    observation : sequence
        One entry per modality: an outcome index, a distribution over the live outcomes, or None.

    Returns
    -------
    tuple of numpy.ndarray
        Per modality ``(obs_capacity[m],)`` float: one-hot, the distribution (zero-padded), or
        zeros (missing). A distribution ``w`` is soft evidence with likelihood
        ``sum_o w(o) A[o, ...]`` (:func:`evidence`), as in the numpy schemes.

    Raises
    ------
    ValueError
        For the wrong number of entries, an outcome out of range, or a distribution that is not a
        vector of at most ``obs_capacity[m]`` finite, non-negative entries summing to 1 (the layout
        does not know the live outcomes: the numpy schemes also refuse mass beyond them).
    """
    if len(observation) != layout.num_modalities:
        raise ValueError(f"an observation has one entry per modality ({layout.num_modalities}), "
                         f"got {len(observation)}")
    out = []
    for m, o in enumerate(observation):
        v = np.zeros(layout.obs_capacity[m])
        if o is None:
            pass
        elif np.ndim(o) == 0:
            if not 0 <= int(o) < layout.obs_capacity[m]:
                raise ValueError(f"modality {m}: outcome {o} out of range [0, {layout.obs_capacity[m]})")
            v[int(o)] = 1.0
        else:
            p = _check_distribution(o, layout.obs_capacity[m], f"modality {m}")
            v[: p.size] = p
        out.append(v)
    return tuple(out)


def _check_distribution(o, capacity: int, what: str) -> np.ndarray:
    """A soft observation as a float vector; refuses what :func:`cogmap.inference.base.prepare` refuses."""
    p = real_array(o, what, ValueError)
    if p.ndim != 1 or not 0 < p.size <= capacity:
        raise ValueError(f"{what}: a distribution over outcomes is a vector of at most {capacity} entries, "
                         f"got shape {p.shape}")
    total = p.sum()
    if not (np.isfinite(total) and p.min() >= 0):
        raise ValueError(f"{what}: distribution entries must be finite and non-negative")
    if abs(total - 1.0) > 1e-6:
        raise ValueError(f"{what}: distribution sums to {total:.6g}, expected 1 (normalise it)")
    return p


def evidence(layout, arrays, obs) -> Evidence:
    """The likelihood of observation vectors ``obs`` (one ``(obs_capacity[m],)`` per modality)."""
    lik = tuple(jnp.tensordot(o, a, axes=1) for o, a in zip(obs, arrays.A, strict=True))
    present = jnp.stack([jnp.sum(o) > 0 for o in obs])
    return Evidence(lik, present)


def _contract(x, deps, qs, keep=None):
    """``x`` (axes = ``deps``, with one leading outcome axis when ``keep == "o"``) contracted with
    the beliefs of its factors, leaving factor ``keep`` (an int), the outcomes (``"o"``) or nothing."""
    lead = 1 if keep == "o" else 0
    args = [x, list(range(lead + len(deps)))]
    for i, f in enumerate(deps):
        if f != keep:
            args += [qs[f], [lead + i]]
    out = [0] if keep == "o" else ([lead + deps.index(keep)] if keep is not None else [])
    return jnp.einsum(*args, out)


def marginal_loglik(ll, deps, qs, f):
    """``E_{q(other deps)}[ll]`` as a function of factor ``f``."""
    if len(deps) == 1:
        return ll
    return _contract(ll, deps, qs, keep=f)


def _logliks(layout, ev: Evidence):
    return [jnp.where(ev.present[m], floor_log(lik), 0.0) for m, lik in enumerate(ev.lik)]


def mean_field_free_energy(layout, qs, log_prior, lls):
    """``sum_f [E log q_f - E log prior_f] - sum_m E_q[ll_m]`` of one time step."""
    fe = 0.0
    for q, lp in zip(qs, log_prior, strict=True):
        fe = fe + xlogx_sum(q) - q @ lp
    for deps, ll in zip(layout.A_deps, lls, strict=True):
        fe = fe - _contract(ll, deps, qs)
    return fe


def fpi(layout, arrays, prior, ev: Evidence, *, num_iter: int = 16, tol: float | None = None):
    """Fixed-point iteration, one time step (the schedule of the numpy ``fpi``).

    Parameters
    ----------
    layout : Layout
    arrays : JaxModel
    prior : tuple of jax.Array
        ``(capacity[f],)`` belief per factor before the observation.
    ev : Evidence
    num_iter : int, optional
        Simultaneous sweeps for several factors (one exact pass for one factor); default 16.
    tol : float, optional
        Stop after the first sweep in which no belief moves by more than ``tol`` (as the numpy
        ``fpi``; under ``vmap`` each agent keeps the beliefs of its own last sweep). Off by default.

    Returns
    -------
    qs : tuple of jax.Array
    free_energy : jax.Array
        Mean-field free energy (nats).
    """
    lls = _logliks(layout, ev)
    log_prior = [floor_log(p) for p in prior]
    F = layout.num_factors
    if F == 1:
        x = log_prior[0]
        for ll in lls:
            x = x + ll
        qs = (masked_softmax(x, arrays.live[0]),)
        return qs, mean_field_free_energy(layout, qs, log_prior, lls)

    # modalities with the same factors are summed once; those of one factor are constant per sweep
    groups: dict = {}
    for deps, ll in zip(layout.A_deps, lls, strict=True):
        groups[deps] = groups[deps] + ll if deps in groups else ll
    const = list(log_prior)
    for deps, ll in groups.items():
        if len(deps) == 1:
            const[deps[0]] = const[deps[0]] + ll
    multi = [(deps, ll) for deps, ll in groups.items() if len(deps) > 1]

    def sweep(_, qs):
        new = []
        for f in range(F):
            x = const[f]
            for deps, ll in multi:
                if f in deps:
                    x = x + marginal_loglik(ll, deps, qs, f)
            new.append(masked_softmax(x, arrays.live[f]))
        return tuple(new)

    start = tuple(lv / jnp.sum(lv) for lv in (jnp.asarray(x, dtype=prior[0].dtype) for x in arrays.live))
    if tol is None:
        qs = jax.lax.fori_loop(0, num_iter, sweep, start, unroll=True)
    else:
        def moving(carry):
            it, _, delta = carry
            return (it < num_iter) & (delta >= tol)

        def body(carry):
            it, qs, _ = carry
            new = sweep(it, qs)
            delta = jnp.max(jnp.stack([jnp.max(jnp.abs(a - b)) for a, b in zip(new, qs, strict=True)]))
            return it + 1, new, delta

        _, qs, _ = jax.lax.while_loop(moving, body, (0, start, jnp.asarray(jnp.inf, dtype=start[0].dtype)))
    return qs, mean_field_free_energy(layout, qs, log_prior, lls)


def _joint(layout, vectors):
    """Outer product of per-factor vectors (factor order)."""
    out = vectors[0]
    for v in vectors[1:]:
        out = jnp.multiply.outer(out, v)
    return out


def _broadcast(layout, x, deps):
    """A tensor over ``deps`` broadcast to the joint state space (factor order)."""
    order = tuple(int(i) for i in np.argsort(deps))
    x = jnp.transpose(x, order)
    shape = [1] * layout.num_factors
    for i in order:
        shape[deps[i]] = x.shape[order.index(i)]
    return x.reshape(shape)


def exact(layout, arrays, prior, ev: Evidence):
    """Exact Bayes over the joint state space, one time step (the prior taken as a product).

    Returns the marginals of the posterior and ``-log p(o | prior)`` as the free energy.
    """
    alpha = _joint(layout, prior)
    lik = jnp.ones_like(alpha)
    for m, (deps, l_m) in enumerate(zip(layout.A_deps, ev.lik, strict=True)):
        lik = lik * jnp.where(ev.present[m], _broadcast(layout, l_m, deps), 1.0)
    post = alpha * lik
    c = jnp.sum(post)
    post = post / c
    F = layout.num_factors
    qs = tuple(jnp.sum(post, axis=tuple(g for g in range(F) if g != f)) if F > 1 else post for f in range(F))
    return qs, -jnp.log(c)


def bayes_filter(layout, arrays, prior, ev: Evidence):
    """AIMAPP's single-factor Bayes filter (exact Bayes for one factor), one time step."""
    if layout.num_factors != 1:
        raise ValueError(f"filter is a single-factor scheme; the model has {layout.num_factors} factors")
    return exact(layout, arrays, prior, ev)


def window(kind: str, layout, arrays, prior, evs: Evidence, actions, *, num_iter: int = 16,
           tau: float | None = None, tol: float | None = None):
    """``vmp``, ``vmp_pymdp`` or ``mmp`` over a whole sequence (the numpy schemes with ``window=None``).

    Parameters
    ----------
    kind : str
        ``"vmp"`` (coordinate ascent, :func:`mean_field_window`), ``"vmp_pymdp"`` or ``"mmp"``
        (pymdp 1.0's simultaneous updates).
    layout, arrays
        The model.
    prior : tuple of jax.Array
        Belief per factor at the first step.
    evs : Evidence
        Stacked over time: ``lik[m]`` has a leading ``T`` axis, ``present`` is ``(T, M)``.
    actions : jax.Array
        ``(T - 1, F)`` int controls.
    num_iter : int, optional
        Sweeps, default 16.
    tau : float, optional
        Step size of ``vmp_pymdp`` and ``mmp`` (default 1); ``vmp`` takes exact coordinate steps
        and refuses it.
    tol : float, optional
        Early stop of ``vmp`` (:func:`mean_field_window`); the other two refuse it.

    Returns
    -------
    qs : tuple of jax.Array
        Per factor ``(T, capacity[f])`` smoothed beliefs.
    terms : jax.Array
        ``(T,)`` per-step terms of the window's mean-field free energy (their sum is the free
        energy of the window; the last is the numpy scheme's ``info.free_energy``).

    Raises
    ------
    ValueError
        For another ``kind``, or an option the scheme does not take.
    """
    if kind not in ("vmp", "vmp_pymdp", "mmp"):
        raise ValueError(f"window runs 'vmp', 'vmp_pymdp' or 'mmp', got {kind!r}")
    if kind == "vmp":
        if tau is not None:
            raise ValueError("tau is an option of vmp_pymdp and mmp, not of 'vmp' (coordinate ascent takes "
                             "exact steps)")
        return mean_field_window(layout, arrays, prior, evs, actions, num_iter=num_iter, tol=tol)
    if tol is not None:
        raise ValueError(f"tol is an option of vmp, not of {kind!r}")
    return _simultaneous_window(kind, layout, arrays, prior, evs, actions, num_iter, 1.0 if tau is None else tau)


def _window_arrays(layout, arrays, prior, evs: Evidence, actions):
    """Floored log-likelihoods ``(T, ...)`` per modality (zero where missing), log priors, the
    transitions ``(T - 1, next, current)`` per factor under ``actions`` and their floored logs."""
    T = evs.present.shape[0]
    F = layout.num_factors
    lls = [jnp.where(evs.present[:, m].reshape((T,) + (1,) * (lik.ndim - 1)), floor_log(lik), 0.0)
           for m, lik in enumerate(evs.lik)]
    log_prior = [floor_log(p) for p in prior]
    actions = jnp.asarray(actions).reshape(T - 1, F)
    Bt = [jnp.moveaxis(arrays.B[f][:, :, actions[:, f]], -1, 0) for f in range(F)]  # (T-1, next, current)
    return lls, log_prior, Bt, [floor_log(b) for b in Bt]


def _uniform_start(arrays, prior, T):
    return tuple(jnp.broadcast_to(lv / jnp.sum(lv), (T, lv.shape[0])).astype(prior[0].dtype)
                 for lv in (jnp.asarray(x, dtype=prior[0].dtype) for x in arrays.live))


def mean_field_window(layout, arrays, prior, evs: Evidence, actions, *, num_iter: int = 16,
                      tol: float | None = None):
    """``vmp``: coordinate ascent on the mean-field free energy of a whole sequence (the numpy
    :func:`cogmap.inference.mean_field.vmp` with ``window=None``).

    Each sweep scans the steps ``t = 0..T-1`` and updates the factors of a step in order, each
    to the minimiser of the free energy given the current other marginals: the previous step's
    (already updated in this sweep), the next step's (from the last sweep) and the other factors
    of the same step.

    Parameters
    ----------
    layout, arrays
        The model.
    prior : tuple of jax.Array
        Belief per factor at the first step.
    evs : Evidence
        Stacked over time: ``lik[m]`` has a leading ``T`` axis, ``present`` is ``(T, M)``.
    actions : jax.Array
        ``(T - 1, F)`` int controls.
    num_iter : int, optional
        Sweeps, default 16.
    tol : float, optional
        Stop after the first sweep in which no belief moves by more than ``tol`` (as the numpy
        scheme; under ``vmap`` each element keeps the beliefs of its own last sweep). Off by
        default.

    Returns
    -------
    qs : tuple of jax.Array
        Per factor ``(T, capacity[f])`` smoothed beliefs.
    terms : jax.Array
        ``(T,)`` per-step terms of the window's mean-field free energy.
    """
    T = evs.present.shape[0]
    F = layout.num_factors
    lls, log_prior, _, logB = _window_arrays(layout, arrays, prior, evs, actions)
    none = [jnp.zeros((1,) + b.shape[1:], dtype=b.dtype) for b in logB]
    into = tuple(jnp.concatenate([z, b]) for z, b in zip(none, logB, strict=True))  # (T, ...): log B_{t-1}
    out_of = tuple(jnp.concatenate([b, z]) for z, b in zip(none, logB, strict=True))  # (T, ...): log B_t
    first = jnp.arange(T) == 0
    last = jnp.arange(T) == T - 1

    def update_step(prev, xs):
        q_t, q_next, ll_t, b_in, b_out, is_first, is_last = xs
        q_t = list(q_t)
        moved = jnp.zeros((), dtype=q_t[0].dtype)
        for f in range(F):
            x = jnp.where(is_first, log_prior[f], b_in[f] @ prev[f])
            x = x + jnp.where(is_last, 0.0, q_next[f] @ b_out[f])
            for deps, ll in zip(layout.A_deps, ll_t, strict=True):
                if f in deps:
                    x = x + marginal_loglik(ll, deps, q_t, f)
            new = masked_softmax(x, arrays.live[f])
            moved = jnp.maximum(moved, jnp.max(jnp.abs(new - q_t[f])))
            q_t[f] = new
        return tuple(q_t), (tuple(q_t), moved)

    def sweep(qs):
        q_next = tuple(jnp.concatenate([q[1:], jnp.zeros_like(q[:1])]) for q in qs)  # the last sweep's q_{t+1}
        init = tuple(jnp.zeros_like(q[0]) for q in qs)
        _, (new, moved) = jax.lax.scan(update_step, init, (qs, q_next, tuple(lls), into, out_of, first, last))
        return new, jnp.max(moved)

    start = _uniform_start(arrays, prior, T)
    if tol is None:
        qs = jax.lax.fori_loop(0, num_iter, lambda _, qs: sweep(qs)[0], start)
    else:
        def moving(carry):
            it, _, delta = carry
            return (it < num_iter) & (delta > tol)

        def body(carry):
            it, qs, _ = carry
            new, delta = sweep(qs)
            return it + 1, new, delta

        _, qs, _ = jax.lax.while_loop(moving, body, (0, start, jnp.asarray(jnp.inf, dtype=start[0].dtype)))
    return qs, window_terms(layout, prior, qs, lls, logB)


def _simultaneous_window(kind, layout, arrays, prior, evs: Evidence, actions, num_iter, tau):
    """``vmp_pymdp`` / ``mmp``: pymdp 1.0's simultaneous updates over a whole sequence."""
    T = evs.present.shape[0]
    F = layout.num_factors
    lls, log_prior, Bt, logB = _window_arrays(layout, arrays, prior, evs, actions)
    Bn = [b / jnp.maximum(jnp.sum(b, axis=2, keepdims=True), LOG_FLOOR) for b in Bt]
    last = jnp.arange(T) == T - 1

    def step_logq(qs, f):
        ln_a = jnp.zeros_like(qs[f])
        for deps, ll in zip(layout.A_deps, lls, strict=True):
            if f in deps:
                ln_a = ln_a + jax.vmap(lambda l_t, *q_t, d=deps: marginal_loglik(l_t, d, q_t, f))(ll, *qs)
        q = qs[f]
        if T == 1:
            fwd = log_prior[f][None]
            bwd = jnp.zeros_like(q)
        elif kind == "vmp_pymdp":
            fwd = jnp.concatenate([log_prior[f][None], jnp.einsum("tij,tj->ti", logB[f], q[:-1])])
            bwd = jnp.concatenate([jnp.einsum("ti,tij->tj", q[1:], logB[f]), jnp.zeros_like(q[:1])])
        else:
            fwd = jnp.concatenate([log_prior[f][None], floor_log(jnp.einsum("tij,tj->ti", Bt[f], q[:-1]))])
            fwd = jnp.where(last[:, None], fwd, 0.5 * fwd)
            bwd = jnp.concatenate([0.5 * floor_log(jnp.einsum("ti,tij->tj", q[1:], Bn[f])), jnp.zeros_like(q[:1])])
        ln_q = floor_log(q)
        return ln_q + tau * (ln_a - ln_q + bwd + fwd)

    def sweep(_, qs):
        return tuple(jax.vmap(masked_softmax, in_axes=(0, None))(step_logq(qs, f), arrays.live[f]) for f in range(F))

    start = _uniform_start(arrays, prior, T)
    qs = jax.lax.fori_loop(0, num_iter, sweep, start, unroll=True)
    return qs, window_terms(layout, prior, qs, lls, logB)


def window_terms(layout, prior, qs, lls, logB):
    """Per-step terms of the mean-field free energy of a window (numpy ``free_energy_terms``)."""
    T = qs[0].shape[0]
    terms = jnp.zeros(T, dtype=qs[0].dtype)
    for f in range(layout.num_factors):
        terms = terms + jax.vmap(xlogx_sum)(qs[f])
        trans = jnp.einsum("ti,tij,tj->t", qs[f][1:], logB[f], qs[f][:-1]) if T > 1 else jnp.zeros(0)
        terms = terms - jnp.concatenate([(qs[f][0] @ floor_log(prior[f]))[None], trans])
    for deps, ll in zip(layout.A_deps, lls, strict=True):
        terms = terms - jax.vmap(lambda l_t, *q_t, d=deps: _contract(l_t, d, q_t))(ll, *qs)
    return terms


def _one_step(kind):
    def scheme(layout, arrays, prior, ev: Evidence, *, num_iter: int = 16, tau: float = 1.0):
        stacked = Evidence(tuple(x[None] for x in ev.lik), ev.present[None])
        qs, terms = window(kind, layout, arrays, prior, stacked, jnp.zeros((0, layout.num_factors), dtype=int),
                           num_iter=num_iter, tau=tau)
        return tuple(q[0] for q in qs), terms[0]

    scheme.__name__ = kind
    scheme.__doc__ = f"``{kind}`` on one time step (the loop's call): :func:`window` with ``T = 1``."
    return scheme


def vmp(layout, arrays, prior, ev: Evidence, *, num_iter: int = 16, tol: float | None = None):
    """``vmp`` on one time step (the loop's call): :func:`mean_field_window` with ``T = 1``.

    With one time step the sweeps run over the factors only (coordinate ascent, one factor at a
    time given the others' current beliefs); a single factor is exact after one sweep.

    Parameters
    ----------
    layout : Layout
    arrays : JaxModel
    prior : tuple of jax.Array
        ``(capacity[f],)`` belief per factor before the observation.
    ev : Evidence
    num_iter : int, optional
        Sweeps, default 16.
    tol : float, optional
        Early stop, as for :func:`mean_field_window`.

    Returns
    -------
    qs : tuple of jax.Array
    free_energy : jax.Array
        Mean-field free energy (nats).
    """
    stacked = Evidence(tuple(x[None] for x in ev.lik), ev.present[None])
    qs, terms = mean_field_window(layout, arrays, prior, stacked, jnp.zeros((0, layout.num_factors), dtype=int),
                                  num_iter=num_iter, tol=tol)
    return tuple(q[0] for q in qs), terms[0]


vmp_pymdp = _one_step("vmp_pymdp")
mmp = _one_step("mmp")

#: the one-step schemes by name (the names of the numpy registry)
SCHEMES = {"exact": exact, "filter": bayes_filter, "fpi": fpi, "vmp": vmp, "vmp_pymdp": vmp_pymdp, "mmp": mmp}
#: the options each accepts
OPTIONS = {"exact": (), "filter": (), "fpi": ("num_iter", "tol"), "vmp": ("num_iter", "tol"),
           "vmp_pymdp": ("num_iter", "tau"), "mmp": ("num_iter", "tau")}


def predict(arrays, qs, action):
    """Per-factor prediction ``B[f][:, :, u_f] q_f`` under controls ``action`` (``(F,)`` int)."""
    return tuple(arrays.B[f][:, :, action[f]] @ q for f, q in enumerate(qs))


__all__ = ["OPTIONS", "SCHEMES", "Evidence", "evidence", "exact", "bayes_filter", "fpi", "mean_field_window", "mmp",
           "one_hot_observation", "predict", "vmp", "vmp_pymdp", "window", "window_terms"]

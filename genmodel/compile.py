"""Validate a :class:`ModelSpec` once and turn it into a :class:`Model` of arrays."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from .likelihood import DenseLikelihood, SparseLikelihood
from .model import Model, PoseModel
from .spec import Factor, Modality, ModelSpec, SparseA, SparseB, SpecError
from .transitions import DenseTransitions, DependentTransitions, SparseTransitions

ATOL = 1e-6
#: largest number of entries of one array a compiled model may reserve (dense A or B at capacity,
#: a sparse factor's successor lists); above it ``compile`` refuses before allocating anything.
MAX_ENTRIES = 2**31


def real_array(value, what: str, error=SpecError) -> np.ndarray:
    """``value`` as a float array; refuses ragged nesting, strings, objects and complex numbers
    (which a plain ``float`` cast would truncate or parse)."""
    try:
        arr = np.asarray(value)
    except (TypeError, ValueError):
        raise error(f"{what}: not a numeric array (nested lists of unequal lengths or mixed types)") from None
    if arr.dtype.kind == "c":
        raise error(f"{what}: complex entries (expected real numbers)")
    if arr.dtype.kind not in "biuf":
        kind = {"U": "strings", "S": "bytes", "O": "objects"}.get(arr.dtype.kind, arr.dtype.name)
        raise error(f"{what}: not a numeric array (got {kind})")
    return arr.astype(float)


def _array(value, what: str) -> np.ndarray:
    arr = real_array(value, what)
    if not np.all(np.isfinite(arr)):
        raise SpecError(f"{what}: contains NaN or infinite entries")
    if np.any(arr < 0):
        raise SpecError(f"{what}: contains negative entries (min {arr.min():.3g})")
    return arr


def _check_normalised(arr: np.ndarray, what: str) -> None:
    sums = arr.sum(axis=0)
    bad = np.abs(sums - 1.0) > ATOL
    if np.any(bad):
        where = tuple(int(i) for i in np.argwhere(bad)[0])
        raise SpecError(
            f"{what}: column {where} sums to {sums[where]:.6g}, expected 1 (columns must be "
            "normalised over the first axis)"
        )


def _check_name(name: str, known: dict, kind: str, where: str) -> None:
    if name not in known:
        raise SpecError(f"{where}: unknown {kind} '{name}' (known: {sorted(known)})")


def _named(item, cls, kind: str, seen: dict) -> None:
    """Refuse a factor or modality that is not a ``cls``, is unnamed or named twice, or whose size is not a count."""
    if not isinstance(item, cls):
        raise SpecError(f"{'factors' if kind == 'factor' else 'modalities'} must be {cls.__name__} instances, "
                        f"got {type(item).__name__}")
    if not isinstance(item.name, str) or not item.name:
        raise SpecError(f"{kind} {item.name!r}: the name must be a non-empty string")
    if item.name in seen:
        raise SpecError(f"{kind} '{item.name}': declared twice")
    _count(item.size, f"{kind} '{item.name}' size")


def _count(value, what: str, minimum: int = 1) -> int:
    """An integer size or count (an int, not a bool, float or string) of at least ``minimum``."""
    if isinstance(value, bool | np.bool_) or not isinstance(value, int | np.integer):
        raise SpecError(f"{what}: must be an integer, got {type(value).__name__} {value!r}")
    if value < minimum:
        raise SpecError(f"{what}: must be >= {minimum}, got {value}")
    return int(value)


def check_entries(shape: tuple[int, ...], what: str, hint: str, max_entries: int = MAX_ENTRIES) -> None:
    """Refuse an array of ``shape`` with more than ``max_entries`` entries, before allocating it."""
    total = 1
    for n in shape:
        total *= int(n)
    if total > max_entries:
        raise SpecError(
            f"{what}: capacity shape {tuple(int(n) for n in shape)} needs {total:.3g} entries, above the limit "
            f"{max_entries:.3g} (lower the capacity, {hint}, or raise max_entries)"
        )


def _capacity(size: int, growable: bool, capacity: int | None, what: str) -> int:
    if capacity is not None:
        capacity = _count(capacity, f"{what} capacity")
    if capacity is None:
        return max(size, 1 << max(0, (size - 1)).bit_length()) if growable else size
    if capacity < size:
        raise SpecError(f"{what}: capacity {capacity} is smaller than size {size}")
    return capacity


def _validate_names(spec: ModelSpec) -> tuple[dict[str, Factor], dict[str, Modality]]:
    for table in ("factors", "modalities"):
        if isinstance(getattr(spec, table), str | bytes | Mapping) or not hasattr(getattr(spec, table), "__iter__"):
            raise SpecError(f"{table}: expected a list of {table[:-1].capitalize()} instances")
    if not spec.factors:
        raise SpecError("factors: empty (a model needs at least one hidden-state factor)")
    if not spec.modalities:
        raise SpecError("modalities: empty (a model needs at least one observation modality)")
    for table in ("A", "B", "C", "D", "pA", "pB", "C_states"):
        if not isinstance(getattr(spec, table), Mapping):
            raise SpecError(f"{table}: expected a dict keyed by name, got {type(getattr(spec, table)).__name__}")
    factors: dict[str, Factor] = {}
    for f in spec.factors:
        _named(f, Factor, "factor", factors)
        _count(f.num_controls, f"factor '{f.name}' num_controls")
        if f.stay is not None:
            _count(f.stay, f"factor '{f.name}' stay", minimum=0)
        if f.stay is not None and not 0 <= f.stay < f.num_controls:
            raise SpecError(f"factor '{f.name}': stay control {f.stay} out of range")
        factors[f.name] = f
    for f in spec.factors:
        _check_factor_deps(f, factors)
    modalities: dict[str, Modality] = {}
    for m in spec.modalities:
        _named(m, Modality, "modality", modalities)
        if isinstance(m.depends_on, str) or not isinstance(m.depends_on, tuple | list):
            raise SpecError(f"modality '{m.name}': depends_on must be a tuple of factor names, got {m.depends_on!r}")
        if not m.depends_on:
            raise SpecError(f"modality '{m.name}': depends on no factor")
        twice = sorted({d for d in m.depends_on if list(m.depends_on).count(d) > 1})
        if twice:
            raise SpecError(f"modality '{m.name}': depends on factor '{twice[0]}' twice (list each factor once)")
        for dep in m.depends_on:
            if dep not in factors:
                raise SpecError(
                    f"modality '{m.name}': depends on missing factor '{dep}' "
                    f"(known: {sorted(factors)})"
                )
        modalities[m.name] = m
    for table, known, kind in (
        ("A", modalities, "modality"),
        ("B", factors, "factor"),
        ("C", modalities, "modality"),
        ("D", factors, "factor"),
        ("pA", modalities, "modality"),
        ("pB", factors, "factor"),
        ("C_states", factors, "factor"),
    ):
        for name in getattr(spec, table):
            _check_name(name, known, kind, f"{table}['{name}']")
    for name in modalities:
        if name not in spec.A:
            raise SpecError(f"A['{name}']: missing likelihood for modality '{name}'")
    for name in factors:
        if name not in spec.B:
            raise SpecError(f"B['{name}']: missing transitions for factor '{name}'")
    return factors, modalities


def _check_factor_deps(fac: Factor, factors: dict[str, Factor]) -> None:
    """Refuse a malformed ``Factor.depends_on`` (as ``Modality.depends_on``, and the factor's own
    previous state must be among its dependencies)."""
    deps = fac.depends_on
    if deps is None:
        return
    what = f"factor '{fac.name}'"
    if isinstance(deps, str) or not isinstance(deps, tuple | list):
        raise SpecError(f"{what}: depends_on must be a tuple of factor names or None, got {deps!r}")
    if not deps:
        raise SpecError(f"{what}: depends_on is empty (leave it None for a factor that depends on itself alone)")
    twice = sorted({d for d in deps if list(deps).count(d) > 1})
    if twice:
        raise SpecError(f"{what}: depends on factor '{twice[0]}' twice (list each factor once)")
    for dep in deps:
        if dep not in factors:
            raise SpecError(f"{what}: depends on missing factor '{dep}' (known: {sorted(factors)})")
    if fac.name not in deps:
        raise SpecError(f"{what}: depends_on {list(deps)} must include the factor itself ('{fac.name}'): "
                        "its next state depends on its own previous state")


def _own_deps(fac: Factor) -> bool:
    """Whether the factor's next state depends on its own previous state alone."""
    return fac.depends_on is None or tuple(fac.depends_on) == (fac.name,)


def compile(spec: ModelSpec, prior_count: float = 1.0, max_entries: int = MAX_ENTRIES) -> Model:  # noqa: A001
    """Validate ``spec`` once and return a :class:`Model` of arrays at capacity.

    Checks shapes, normalisation, non-negativity, finiteness and names; dense likelihoods and
    transitions are padded to the reserved capacity (columns of not-yet-live states are filled so
    that every column stays normalised).

    Parameters
    ----------
    spec : ModelSpec
        The model specification.
    prior_count : float, optional
        Positive Dirichlet count given to new states and outcomes during growth, default 1.
    max_entries : int, optional
        Bound on the entries of any one reserved array, checked before allocating.

    Returns
    -------
    Model
        The compiled model.

    Raises
    ------
    SpecError
        Naming the factor or modality and the problem, for an invalid spec, a non-positive
        ``prior_count``, arrays above ``max_entries`` or a failed allocation.
    """
    if not isinstance(spec, ModelSpec):
        raise SpecError(f"compile() expects a ModelSpec, got {type(spec).__name__}")
    if isinstance(prior_count, bool) or not isinstance(prior_count, int | float | np.integer | np.floating) \
            or not np.isfinite(prior_count) or prior_count <= 0:
        raise SpecError(f"prior_count: must be a positive finite number, got {prior_count!r}")
    cp = spec.collision_preference
    if cp is not None and (isinstance(cp, bool) or not isinstance(cp, int | float | np.integer | np.floating)
                           or not np.isfinite(cp)):
        raise SpecError(f"collision_preference: must be a finite number (a log-preference) or None, got {cp!r}")
    factors, modalities = _validate_names(spec)
    try:
        return _compile(spec, factors, prior_count, max_entries)
    except MemoryError:
        raise SpecError(
            "not enough memory for the arrays at the declared capacities (lower the capacities, or give "
            "SparseA/SparseB for large growable factors)"
        ) from None


def _compile(spec: ModelSpec, factors: dict[str, Factor], prior_count: float, max_entries: int) -> Model:
    order_f = [f.name for f in spec.factors]
    cap_f = {f.name: _capacity(f.size, f.growable, f.capacity, f"factor '{f.name}'") for f in spec.factors}
    cap_m = {
        m.name: _capacity(m.size, m.growable, m.capacity, f"modality '{m.name}'")
        for m in spec.modalities
    }
    _check_sizes(spec, factors, cap_f, cap_m, max_entries)

    A, C, A_deps = [], [], []
    for mod in spec.modalities:
        shape = (mod.size,) + tuple(factors[d].size for d in mod.depends_on)
        what = f"A['{mod.name}']"
        cap_shape = (cap_m[mod.name],) + tuple(cap_f[d] for d in mod.depends_on)
        A_deps.append(tuple(order_f.index(d) for d in mod.depends_on))
        C.append(_preferences(spec, mod, cap_m[mod.name]))
        if isinstance(spec.A[mod.name], SparseA):
            A.append(_sparse_A_from_spec(spec, mod, factors, cap_shape))
            continue
        a = _array(spec.A[mod.name], what)
        if a.shape != shape:
            raise SpecError(f"{what}: shape {a.shape}, expected {shape} (outcomes, *depends_on)")
        _check_normalised(a, what)
        full = np.zeros(cap_shape)
        full[tuple(slice(0, n) for n in shape)] = a
        _fill_dead_columns(full, shape)
        pfull = None
        if mod.name in spec.pA:
            p = _array(spec.pA[mod.name], f"pA['{mod.name}']")
            if p.shape != shape:
                raise SpecError(f"pA['{mod.name}']: shape {p.shape}, expected {shape}")
            if np.any(p.sum(axis=0) <= 0):
                raise SpecError(f"pA['{mod.name}']: a column has no positive count")
            pfull = np.zeros(cap_shape)
            pfull[tuple(slice(0, n) for n in shape)] = p
        A.append(DenseLikelihood(full, pfull, mod.size, shape[1:]))

    B, D, C_states, B_deps = [], [], [], []
    for f_idx, fac in enumerate(spec.factors):
        n, u, cap = fac.size, fac.num_controls, cap_f[fac.name]
        what = f"B['{fac.name}']"
        raw = spec.B[fac.name]
        counts = None
        multi = not _own_deps(fac)  # the next state depends on the previous states of several factors
        if fac.name in spec.pB and not multi:
            counts = _array(spec.pB[fac.name], f"pB['{fac.name}']")
            if counts.shape != (n, n, u):
                raise SpecError(f"pB['{fac.name}']: shape {counts.shape}, expected {(n, n, u)}")
        if multi:
            B.append(_dependent_from_spec(spec, fac, factors, order_f, cap_f))
        elif isinstance(raw, SparseB):
            if raw.counts is not None:
                if counts is not None:
                    raise SpecError(f"pB['{fac.name}']: the SparseB holds its own counts; give them once")
                counts = _array(raw.counts, f"{what}.counts")
                if counts.shape != np.shape(raw.prob):
                    raise SpecError(f"{what}.counts: shape {counts.shape}, expected {np.shape(raw.prob)} (as prob)")
                if np.any(counts < 0):
                    raise SpecError(f"{what}.counts: negative count")
            B.append(_sparse_from_spec(raw, fac, cap, counts))
        else:
            b = _array(raw, what)
            if b.shape != (n, n, u):
                raise SpecError(f"{what}: shape {b.shape}, expected {(n, n, u)} (next, current, control)")
            _check_normalised(b, what)
            if fac.stay is not None and not np.allclose(b[:, :, fac.stay], np.eye(n)):
                raise SpecError(f"{what}: stay control {fac.stay} must be the identity")
            full = np.zeros((cap, cap, u))
            full[:n, :n] = b
            full[np.arange(n, cap), np.arange(n, cap), :] = 1.0
            pfull = None
            if counts is not None:
                _check_counts_support(b, counts, f"pB['{fac.name}']", what)
                pfull = np.zeros((cap, cap, u))
                pfull[:n, :n] = counts
            B.append(DenseTransitions(full, pfull))
        B_deps.append(B[-1].deps if multi else (f_idx,))
        d = np.zeros(cap)
        if fac.name in spec.D:
            dv = _array(spec.D[fac.name], f"D['{fac.name}']")
            if dv.shape != (n,):
                raise SpecError(f"D['{fac.name}']: shape {dv.shape}, expected ({n},)")
            if abs(dv.sum() - 1.0) > ATOL:
                raise SpecError(f"D['{fac.name}']: sums to {dv.sum():.6g}, expected 1")
            d[:n] = dv
        else:
            d[:n] = 1.0 / n
        D.append(d)
        cs = np.zeros(cap)
        if fac.name in spec.C_states:
            cv = real_array(spec.C_states[fac.name], f"C_states['{fac.name}']")
            if cv.shape != (n,) or not np.all(np.isfinite(cv)):
                raise SpecError(f"C_states['{fac.name}']: expected ({n},) finite values")
            cs[:n] = cv
        C_states.append(cs)

    pose = _pose_from_spec(spec, factors, order_f, cap_f)
    if spec.inductive is not None:
        ind = spec.inductive
        if not 0 <= ind.threshold <= 1 or ind.depth < 1:
            raise SpecError("inductive: threshold must be in [0, 1] and depth >= 1")
    return Model(
        factors=tuple(spec.factors),
        modalities=tuple(spec.modalities),
        A=A,
        A_deps=tuple(A_deps),
        B=B,
        B_deps=tuple(B_deps),
        C=C,
        D=D,
        C_states=C_states,
        num_states=[f.size for f in spec.factors],
        num_obs=[m.size for m in spec.modalities],
        pose=pose,
        inductive=spec.inductive,
        collision_preference=spec.collision_preference,
        prior_count=prior_count,
    )


def _dependent_from_spec(spec: ModelSpec, fac: Factor, factors, order_f, cap_f) -> DependentTransitions:
    """Dense transitions of a factor whose next state depends on several factors' previous states."""
    what = f"B['{fac.name}']"
    deps = tuple(fac.depends_on)
    raw = spec.B[fac.name]
    if isinstance(raw, SparseB):
        raise SpecError(f"{what}: a SparseB cannot depend on other factors (depends_on {list(deps)}); "
                        "give a dense array shaped (next, *depends_on, control)")
    for name in deps:
        dep = factors[name]
        if dep.growable or cap_f[name] != dep.size:
            kind = "growable" if dep.growable else f"padded to capacity {cap_f[name]}"
            who = "it is" if name == fac.name else f"factor '{name}' is"
            raise SpecError(f"factor '{fac.name}': depends_on {list(deps)} is only supported between factors of "
                            f"fixed size ({who} {kind}); drop growable/capacity or the extra dependencies")
        if isinstance(spec.B[name], SparseB) and name != fac.name:
            raise SpecError(f"factor '{fac.name}': depends on factor '{name}', whose transitions are a SparseB "
                            "(dependencies are supported between dense factors only)")
    shape = (fac.size,) + tuple(factors[d].size for d in deps) + (fac.num_controls,)
    b = _array(raw, what)
    if b.shape != shape:
        raise SpecError(f"{what}: shape {b.shape}, expected {shape} (next, *depends_on {list(deps)}, control)")
    _check_normalised(b, what)
    own = deps.index(fac.name)
    if fac.stay is not None:
        eye = np.eye(fac.size).reshape((fac.size,) + tuple(fac.size if i == own else 1 for i in range(len(deps))))
        if not np.allclose(b[..., fac.stay], np.broadcast_to(eye, shape[:-1])):
            raise SpecError(f"{what}: stay control {fac.stay} must keep the factor's own state, whatever the "
                            "states of its other dependencies")
    counts = None
    if fac.name in spec.pB:
        counts = _array(spec.pB[fac.name], f"pB['{fac.name}']")
        if counts.shape != shape:
            raise SpecError(f"pB['{fac.name}']: shape {counts.shape}, expected {shape} (as B['{fac.name}'])")
        bad = (b > 0) & (counts <= 0)
        if np.any(bad):
            idx = tuple(int(i) for i in np.argwhere(bad)[0])
            raise SpecError(f"pB['{fac.name}']: count 0 at {idx} (next, *depends_on, control) where {what} is "
                            f"{b[idx]:.6g}; the counts must be positive wherever B is")
    return DependentTransitions(b, tuple(order_f.index(d) for d in deps), counts, fac.name)


def _check_counts_support(prob: np.ndarray, counts: np.ndarray, what: str, of: str, slots: bool = False) -> None:
    """Refuse counts that contradict the transitions they belong to: learning sets each column of
    ``B`` to its normalised counts (:meth:`DenseTransitions.learn`, ``learn_soft``), so a count of 0
    where ``B`` is positive would make a transition ``B`` believes possible impossible at the first
    update. Counts where ``B`` is 0 are a soft prior (the move becomes possible once learnt) and are
    accepted. ``slots``: ``prob`` and ``counts`` are sparse ``(state, control, slot)`` arrays."""
    bad = (prob > 0) & (counts <= 0)
    if np.any(bad):
        idx = tuple(int(i) for i in np.argwhere(bad)[0])
        if slots:
            at = f"state {idx[0]}, control {idx[1]}, slot {idx[2]}"
        else:
            at = f"next {idx[0]}, current {idx[1]}, control {idx[2]}"
        raise SpecError(f"{what}: count 0 at ({at}) where {of} is {prob[idx]:.6g}; learning sets each column of "
                        f"B to its normalised counts, so the counts must be positive wherever B is")


def _check_sizes(spec: ModelSpec, factors, cap_f, cap_m, max_entries: int) -> None:
    """Refuse capacities whose arrays would exceed ``max_entries`` entries, before allocating."""
    for mod in spec.modalities:
        check_entries((cap_m[mod.name],), f"C['{mod.name}']", "lower the modality's capacity", max_entries)
        if isinstance(spec.A[mod.name], SparseA):  # stored per state: (capacity, slots)
            check_entries((cap_f[mod.depends_on[0]], 4), f"A['{mod.name}']", "or fewer states", max_entries)
            continue
        shape = (cap_m[mod.name],) + tuple(cap_f[d] for d in mod.depends_on)
        check_entries(shape, f"A['{mod.name}']", "or give a SparseA for a modality over one growable factor",
                      max_entries)
    for fac in spec.factors:
        cap, u = cap_f[fac.name], fac.num_controls
        raw = spec.B[fac.name]
        if not _own_deps(fac):
            shape = (cap,) + tuple(cap_f[d] for d in fac.depends_on) + (u,)
            check_entries(shape, f"B['{fac.name}']", "or fewer dependencies", max_entries)
        elif isinstance(raw, SparseB):
            slots = np.shape(raw.succ)[2] if len(np.shape(raw.succ)) == 3 else 1
            check_entries((cap, u, slots), f"B['{fac.name}']", "or fewer successor slots", max_entries)
        else:
            check_entries((cap, cap, u), f"B['{fac.name}']", "or give a SparseB (successor lists)", max_entries)


def _preferences(spec: ModelSpec, mod: Modality, cap: int) -> np.ndarray:
    c = np.zeros(cap)
    if mod.name in spec.C:
        cv = real_array(spec.C[mod.name], f"C['{mod.name}']")
        if cv.shape != (mod.size,):
            raise SpecError(f"C['{mod.name}']: shape {cv.shape}, expected ({mod.size},)")
        if not np.all(np.isfinite(cv)):
            raise SpecError(f"C['{mod.name}']: contains NaN or infinite entries")
        c[: mod.size] = cv
    return c


def _sparse_A_from_spec(spec: ModelSpec, mod: Modality, factors, cap_shape) -> SparseLikelihood:
    what = f"A['{mod.name}']"
    raw = spec.A[mod.name]
    if len(mod.depends_on) != 1:
        raise SpecError(f"{what}: a SparseA depends on exactly one factor, not {len(mod.depends_on)}")
    if mod.name in spec.pA:
        raise SpecError(f"pA['{mod.name}']: a SparseA holds its own counts; give them once, in A['{mod.name}']")
    n = factors[mod.depends_on[0]].size
    prior = _array(raw.prior, f"{what}.prior")
    if prior.shape != (n,):
        raise SpecError(f"{what}.prior: shape {prior.shape}, expected ({n},) (one concentration per state)")
    o_idx, s_idx = np.asarray(raw.outcomes).ravel(), np.asarray(raw.states).ravel()
    counts = real_array(raw.counts, f"{what}.counts").ravel()
    if not (o_idx.size == s_idx.size == counts.size):
        raise SpecError(f"{what}: outcomes, states and counts must have the same length")
    if o_idx.size and (not np.issubdtype(o_idx.dtype, np.integer) or not np.issubdtype(s_idx.dtype, np.integer)):
        raise SpecError(f"{what}: outcomes and states must be integer indices")
    if o_idx.size and (o_idx.min() < 0 or o_idx.max() >= mod.size or s_idx.min() < 0 or s_idx.max() >= n):
        raise SpecError(f"{what}: an index is out of range (outcomes 0..{mod.size - 1}, states 0..{n - 1})")
    if not np.all(np.isfinite(counts)) or np.any(counts < 0):
        raise SpecError(f"{what}.counts: must be finite and non-negative")
    total = prior + np.bincount(s_idx.astype(np.int64), weights=counts, minlength=n)
    if np.any(total <= 0):
        raise SpecError(f"{what}: state {int(np.flatnonzero(total <= 0)[0])} has no positive count")
    return SparseLikelihood.from_counts(prior, (mod.size, o_idx, s_idx, counts), capacity=cap_shape[1])


def _fill_dead_columns(full: np.ndarray, live_shape: tuple[int, ...]) -> None:
    """Columns of not-yet-live states get a uniform distribution over live outcomes."""
    n_o = live_shape[0]
    if full.ndim == 1:
        return
    col_live = np.zeros(full.shape[1:], dtype=bool)
    col_live[tuple(slice(0, n) for n in live_shape[1:])] = True
    full[:n_o, ~col_live] = 1.0 / n_o


def _sparse_from_spec(raw: SparseB, fac: Factor, cap: int, counts) -> SparseTransitions:
    what = f"B['{fac.name}']"
    try:
        succ = np.asarray(raw.succ)
    except (TypeError, ValueError):
        raise SpecError(f"{what}.succ: not an integer array") from None
    prob = _array(raw.prob, f"{what}.prob")
    n, u = fac.size, fac.num_controls
    if succ.ndim != 3 or succ.shape[:2] != (n, u) or prob.shape != succ.shape:
        raise SpecError(f"{what}: succ/prob must both have shape ({n}, {u}, slots)")
    if not np.issubdtype(succ.dtype, np.integer) or succ.min() < 0 or succ.max() >= n:
        raise SpecError(f"{what}: successor indices must be integers in [0, {n})")
    sums = prob.sum(axis=2)
    if np.any(np.abs(sums - 1.0) > ATOL):
        s, a = (int(i) for i in np.argwhere(np.abs(sums - 1.0) > ATOL)[0])
        raise SpecError(f"{what}: column (state {s}, control {a}) sums to {sums[s, a]:.6g}, expected 1")
    out = SparseTransitions.empty(cap, u, succ.shape[2], with_counts=counts is not None)
    out.succ[:n] = succ
    out.prob[:n] = prob
    if counts is not None and counts.shape == prob.shape:  # sparse counts, slot by slot
        _check_counts_support(prob, counts, f"{what}.counts", what, slots=True)
        out.counts[:n] = counts
    elif counts is not None:  # dense (n, n, u) counts read at the successors
        s_idx = np.arange(n)[:, None, None]
        a_idx = np.arange(u)[None, :, None]
        out.counts[:n] = np.where(prob > 0, counts[succ, s_idx, a_idx], 0.0)
        _check_counts_support(prob, out.counts[:n], f"pB['{fac.name}']", what, slots=True)
    if fac.stay is not None:
        stay_ok = np.all(
            np.isclose(out.prob[:n, fac.stay][np.arange(n), 0], 1.0)
            & (out.succ[:n, fac.stay, 0] == np.arange(n))
        )
        if not stay_ok:
            raise SpecError(f"{what}: stay control {fac.stay} must be the identity")
    return out


def _pose_from_spec(spec: ModelSpec, factors, order_f, cap_f) -> PoseModel | None:
    ps = spec.pose
    if ps is None:
        return None
    _check_name(ps.factor, factors, "factor", "pose")
    fac = factors[ps.factor]
    poses = real_array(ps.poses, "pose: poses")
    if poses.shape != (fac.size, 2) or not np.all(np.isfinite(poses)):
        raise SpecError(f"pose: poses must be finite with shape ({fac.size}, 2), got {poses.shape}")
    headings = real_array(ps.headings, "pose: headings").ravel()
    if not np.all(np.isfinite(headings)):
        raise SpecError("pose: headings must be finite")
    n_moves = fac.num_controls - (1 if fac.stay is not None else 0)
    if headings.shape != (n_moves,):
        raise SpecError(f"pose: {n_moves} headings expected (one per non-stay control), got {headings.size}")
    for key in ("step", "influence_radius") + (("sigma",) if ps.sigma is not None else ()):
        v = getattr(ps, key)
        if isinstance(v, bool) or not isinstance(v, int | float | np.integer | np.floating) or not np.isfinite(v):
            raise SpecError(f"pose: {key} must be a finite number, got {v!r}")
    if ps.step <= 0 or ps.influence_radius <= 0 or (ps.sigma is not None and ps.sigma <= 0):
        raise SpecError("pose: step, influence_radius and sigma must be positive")
    full = np.zeros((cap_f[ps.factor], 2))
    full[: fac.size] = poses
    sigma = ps.sigma if ps.sigma is not None else ps.influence_radius / 2
    return PoseModel(
        order_f.index(ps.factor), full, headings, float(ps.step), float(ps.influence_radius), float(sigma)
    )

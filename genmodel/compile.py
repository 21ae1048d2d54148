"""Validate a :class:`ModelSpec` once and turn it into a :class:`Model` of arrays."""

from __future__ import annotations

import numpy as np

from .likelihood import DenseLikelihood, SparseLikelihood
from .model import Model, PoseModel
from .spec import Factor, Modality, ModelSpec, SparseA, SparseB, SpecError
from .transitions import DenseTransitions, SparseTransitions

ATOL = 1e-6


def _array(value, what: str) -> np.ndarray:
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as err:
        raise SpecError(f"{what}: not a numeric array ({err})") from None
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


def _capacity(size: int, growable: bool, capacity: int | None, what: str) -> int:
    if capacity is None:
        return max(size, 1 << max(0, (size - 1)).bit_length()) if growable else size
    if capacity < size:
        raise SpecError(f"{what}: capacity {capacity} is smaller than size {size}")
    return capacity


def _validate_names(spec: ModelSpec) -> tuple[dict[str, Factor], dict[str, Modality]]:
    factors: dict[str, Factor] = {}
    for f in spec.factors:
        if not isinstance(f, Factor):
            raise SpecError(f"factors must be Factor instances, got {type(f).__name__}")
        if f.name in factors:
            raise SpecError(f"factor '{f.name}': declared twice")
        if f.size < 1 or f.num_controls < 1:
            raise SpecError(f"factor '{f.name}': size and num_controls must be >= 1")
        if f.stay is not None and not 0 <= f.stay < f.num_controls:
            raise SpecError(f"factor '{f.name}': stay control {f.stay} out of range")
        factors[f.name] = f
    modalities: dict[str, Modality] = {}
    for m in spec.modalities:
        if not isinstance(m, Modality):
            raise SpecError(f"modalities must be Modality instances, got {type(m).__name__}")
        if m.name in modalities:
            raise SpecError(f"modality '{m.name}': declared twice")
        if m.size < 1:
            raise SpecError(f"modality '{m.name}': size must be >= 1")
        if not m.depends_on:
            raise SpecError(f"modality '{m.name}': depends on no factor")
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


def compile(spec: ModelSpec, prior_count: float = 1.0) -> Model:  # noqa: A001 - public API name
    """Validate ``spec`` and return a :class:`Model`; raises :class:`SpecError` naming the
    factor or modality and the problem."""
    if not isinstance(spec, ModelSpec):
        raise SpecError(f"compile() expects a ModelSpec, got {type(spec).__name__}")
    factors, modalities = _validate_names(spec)
    order_f = [f.name for f in spec.factors]
    cap_f = {f.name: _capacity(f.size, f.growable, f.capacity, f"factor '{f.name}'") for f in spec.factors}
    cap_m = {
        m.name: _capacity(m.size, m.growable, m.capacity, f"modality '{m.name}'")
        for m in spec.modalities
    }

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

    B, D, C_states = [], [], []
    for fac in spec.factors:
        n, u, cap = fac.size, fac.num_controls, cap_f[fac.name]
        what = f"B['{fac.name}']"
        raw = spec.B[fac.name]
        counts = None
        if fac.name in spec.pB:
            counts = _array(spec.pB[fac.name], f"pB['{fac.name}']")
            if counts.shape != (n, n, u):
                raise SpecError(f"pB['{fac.name}']: shape {counts.shape}, expected {(n, n, u)}")
        if isinstance(raw, SparseB):
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
                pfull = np.zeros((cap, cap, u))
                pfull[:n, :n] = counts
            B.append(DenseTransitions(full, pfull))
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
            cv = np.asarray(spec.C_states[fac.name], dtype=float)
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


def _preferences(spec: ModelSpec, mod: Modality, cap: int) -> np.ndarray:
    c = np.zeros(cap)
    if mod.name in spec.C:
        cv = np.asarray(spec.C[mod.name], dtype=float)
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
    counts = np.asarray(raw.counts, dtype=float).ravel()
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
    succ = np.asarray(raw.succ)
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
        out.counts[:n] = counts
    elif counts is not None:  # dense (n, n, u) counts read at the successors
        s_idx = np.arange(n)[:, None, None]
        a_idx = np.arange(u)[None, :, None]
        out.counts[:n] = np.where(prob > 0, counts[succ, s_idx, a_idx], 0.0)
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
    poses = np.asarray(ps.poses, dtype=float)
    if poses.shape != (fac.size, 2) or not np.all(np.isfinite(poses)):
        raise SpecError(f"pose: poses must be finite with shape ({fac.size}, 2), got {poses.shape}")
    headings = np.asarray(ps.headings, dtype=float).ravel()
    n_moves = fac.num_controls - (1 if fac.stay is not None else 0)
    if headings.shape != (n_moves,):
        raise SpecError(f"pose: {n_moves} headings expected (one per non-stay control), got {headings.size}")
    if ps.step <= 0 or ps.influence_radius <= 0:
        raise SpecError("pose: step and influence_radius must be positive")
    full = np.zeros((cap_f[ps.factor], 2))
    full[: fac.size] = poses
    sigma = ps.sigma if ps.sigma is not None else ps.influence_radius / 2
    return PoseModel(
        order_f.index(ps.factor), full, headings, float(ps.step), float(ps.influence_radius), float(sigma)
    )

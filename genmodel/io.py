"""Save and load models as ``<stem>.npz`` (arrays) + ``<stem>.json`` (structure). No pickle.

The JSON records factors, modalities, live sizes, dependencies, settings and the SHA-256 of the
npz file, so a truncated, corrupt or mismatched pair is refused with a clear error.
"""

from __future__ import annotations

import hashlib
import json
import zipfile
from dataclasses import asdict
from pathlib import Path

import numpy as np

from .likelihood import DenseLikelihood, SparseLikelihood
from .model import Model, PoseModel
from .spec import Factor, InductiveSpec, Modality, SpecError
from .transitions import DenseTransitions, SparseTransitions

FORMAT = "cogmap-model"
VERSION = 2  # 2: sparse likelihoods (SparseA) saved as their counts; version 1 files still load
READABLE = (1, 2)


class ModelFileError(SpecError):
    """A saved model is missing, truncated, corrupt or inconsistent."""


def _paths(path) -> tuple[Path, Path]:
    p = Path(path)
    stem = p.with_suffix("") if p.suffix in (".npz", ".json") else p
    return stem.with_suffix(".npz"), stem.with_suffix(".json")


def save(model: Model, path) -> tuple[Path, Path]:
    """Write the model; returns the (npz, json) paths. Arrays are saved at live sizes."""
    npz_path, json_path = _paths(path)
    npz_path.parent.mkdir(parents=True, exist_ok=True)
    arrays: dict[str, np.ndarray] = {}
    for m in range(len(model.modalities)):
        arrays[f"C{m}"] = model.live_C(m)
        if model.is_sparse_A(m):  # the counts only: A is their normalisation
            L = model.A[m]
            n = L.num_states
            arrays[f"Aprior{m}"] = L.prior[:n]
            arrays[f"Aobs{m}"] = L.obs[:n]
            arrays[f"Acnt{m}"] = L.cnt[:n]
            continue
        arrays[f"A{m}"] = model.live_A(m)
        if model.A[m].has_counts:
            arrays[f"pA{m}"] = model.live_pA(m)
    for f in range(len(model.factors)):
        n = model.num_states[f]
        B = model.B[f]
        if isinstance(B, SparseTransitions):
            arrays[f"Bsucc{f}"] = B.succ[:n]
            arrays[f"Bprob{f}"] = B.prob[:n]
            if B.counts is not None:
                arrays[f"Bcounts{f}"] = B.counts[:n]
        else:
            arrays[f"B{f}"] = B.to_dense(n)
            if B.counts is not None:
                arrays[f"pB{f}"] = B.counts_dense(n)
        arrays[f"D{f}"] = model.live_D(f)
        arrays[f"Cs{f}"] = model.C_states[f][:n]
    if model.pose is not None:
        arrays["poses"] = model.pose.poses[: model.num_states[model.pose.factor]]
        arrays["headings"] = model.pose.headings
    with open(npz_path, "wb") as fh:
        np.savez_compressed(fh, **arrays)
    meta = {
        "format": FORMAT,
        "version": VERSION,
        "factors": [asdict(f) for f in model.factors],
        "modalities": [asdict(m) for m in model.modalities],
        "num_states": list(model.num_states),
        "num_obs": list(model.num_obs),
        "A_deps": [list(d) for d in model.A_deps],
        "sparse": [model.is_sparse(f) for f in range(len(model.factors))],
        "sparse_A": [model.is_sparse_A(m) for m in range(len(model.modalities))],
        "capacities": [model.state_capacity(f) for f in range(len(model.factors))],
        "obs_capacities": [model.obs_capacity(m) for m in range(len(model.modalities))],
        "prior_count": model.prior_count,
        "collision_preference": model.collision_preference,
        "inductive": None if model.inductive is None else asdict(model.inductive),
        "pose": None
        if model.pose is None
        else {
            "factor": model.pose.factor,
            "step": model.pose.step,
            "influence_radius": model.pose.influence_radius,
            "sigma": model.pose.sigma,
        },
        "npz_sha256": hashlib.sha256(npz_path.read_bytes()).hexdigest(),
        "arrays": sorted(arrays),
    }
    json_path.write_text(json.dumps(meta, indent=1))
    return npz_path, json_path


def load(path) -> Model:
    """Read a model written by :func:`save`; raises :class:`ModelFileError` on any damage."""
    npz_path, json_path = _paths(path)
    for p in (npz_path, json_path):
        if not p.exists():
            raise ModelFileError(f"{p}: file not found")
    try:
        meta = json.loads(json_path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as err:
        raise ModelFileError(f"{json_path}: not valid JSON ({err})") from None
    if not isinstance(meta, dict) or meta.get("format") != FORMAT:
        raise ModelFileError(f"{json_path}: not a cogmap model description")
    if meta.get("version") not in READABLE:
        raise ModelFileError(f"{json_path}: format version {meta.get('version')} is not supported "
                             f"(this cogmap reads versions {', '.join(map(str, READABLE))})")
    digest = hashlib.sha256(npz_path.read_bytes()).hexdigest()
    if digest != meta.get("npz_sha256"):
        raise ModelFileError(f"{npz_path}: contents do not match {json_path.name} (truncated or corrupt)")
    try:
        with np.load(npz_path, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
    except (zipfile.BadZipFile, ValueError, OSError, EOFError) as err:
        raise ModelFileError(f"{npz_path}: unreadable array archive ({err})") from None
    missing = set(meta["arrays"]) - set(arrays)
    if missing:
        raise ModelFileError(f"{npz_path}: missing arrays {sorted(missing)}")
    try:
        return _rebuild(meta, arrays)
    except ModelFileError:
        raise
    except (KeyError, TypeError, IndexError, ValueError) as err:
        raise ModelFileError(f"{json_path}: inconsistent model description ({err})") from None


def _rebuild(meta: dict, arrays: dict[str, np.ndarray]) -> Model:
    factors = tuple(
        Factor(**{**f, "control_names": None if f["control_names"] is None else tuple(f["control_names"])})
        for f in meta["factors"]
    )
    modalities = tuple(Modality(**{**m, "depends_on": tuple(m["depends_on"])}) for m in meta["modalities"])
    ns, no = list(meta["num_states"]), list(meta["num_obs"])
    caps, ocaps = meta["capacities"], meta["obs_capacities"]
    deps = tuple(tuple(d) for d in meta["A_deps"])
    A, C = [], []
    sparse_A = meta.get("sparse_A", [False] * len(deps))
    for m, d in enumerate(deps):
        c = np.zeros(ocaps[m])
        c[: no[m]] = _check(arrays[f"C{m}"], (no[m],), f"C{m}")
        C.append(c)
        if sparse_A[m]:
            A.append(_sparse_likelihood(arrays, m, no[m], ns[d[0]], caps[d[0]]))
            continue
        shape = (ocaps[m],) + tuple(caps[f] for f in d)
        live = (slice(0, no[m]),) + tuple(slice(0, ns[f]) for f in d)
        a = np.zeros(shape)
        a[live] = _check(arrays[f"A{m}"], (no[m],) + tuple(ns[f] for f in d), f"A{m}")
        if modalities[m].size and a.ndim > 1:
            dead = np.ones(shape[1:], dtype=bool)
            dead[live[1:]] = False
            a[: no[m], dead] = 1.0 / max(1, no[m])
        p = None
        if f"pA{m}" in arrays:
            p = np.zeros(shape)
            p[live] = _check(arrays[f"pA{m}"], a[live].shape, f"pA{m}")
        A.append(DenseLikelihood(a, p, no[m], tuple(ns[f] for f in d)))
    B, D, Cs = [], [], []
    for f, fac in enumerate(factors):
        n, cap, u = ns[f], caps[f], fac.num_controls
        if meta["sparse"][f]:
            succ = arrays[f"Bsucc{f}"]
            k = succ.shape[2]
            t = SparseTransitions.empty(cap, u, k, with_counts=f"Bcounts{f}" in arrays)
            t.succ[:n] = _check(succ, (n, u, k), f"Bsucc{f}")
            t.prob[:n] = _check(arrays[f"Bprob{f}"], (n, u, k), f"Bprob{f}")
            if t.counts is not None:
                t.counts[:n] = _check(arrays[f"Bcounts{f}"], (n, u, k), f"Bcounts{f}")
            B.append(t)
        else:
            b = np.zeros((cap, cap, u))
            b[:n, :n] = _check(arrays[f"B{f}"], (n, n, u), f"B{f}")
            b[np.arange(n, cap), np.arange(n, cap), :] = 1.0
            p = None
            if f"pB{f}" in arrays:
                p = np.zeros((cap, cap, u))
                p[:n, :n] = _check(arrays[f"pB{f}"], (n, n, u), f"pB{f}")
            B.append(DenseTransitions(b, p))
        d = np.zeros(cap)
        d[:n] = _check(arrays[f"D{f}"], (n,), f"D{f}")
        D.append(d)
        cs = np.zeros(cap)
        cs[:n] = _check(arrays[f"Cs{f}"], (n,), f"Cs{f}")
        Cs.append(cs)
    pose = None
    if meta["pose"] is not None:
        pm = meta["pose"]
        pf = pm["factor"]
        poses = np.zeros((caps[pf], 2))
        poses[: ns[pf]] = _check(arrays["poses"], (ns[pf], 2), "poses")
        pose = PoseModel(pf, poses, arrays["headings"], pm["step"], pm["influence_radius"], pm["sigma"])
    model = Model(
        factors=factors,
        modalities=modalities,
        A=A,
        A_deps=deps,
        B=B,
        C=C,
        D=D,
        C_states=Cs,
        num_states=ns,
        num_obs=no,
        pose=pose,
        inductive=None if meta["inductive"] is None else InductiveSpec(**meta["inductive"]),
        collision_preference=meta["collision_preference"],
        prior_count=meta["prior_count"],
    )
    _check_normalised(model)
    return model


def _sparse_likelihood(arrays: dict, m: int, num_obs: int, n: int, cap: int) -> SparseLikelihood:
    obs = arrays[f"Aobs{m}"]
    if obs.ndim != 2 or obs.shape[0] != n or obs.dtype.kind not in "iu":
        raise ModelFileError(f"array Aobs{m}: shape {obs.shape} ({obs.dtype}), expected integers ({n}, slots)")
    cnt = _check(arrays[f"Acnt{m}"], obs.shape, f"Acnt{m}")
    prior = _check(arrays[f"Aprior{m}"], (n,), f"Aprior{m}")
    if obs.size and (obs.min() < -1 or obs.max() >= num_obs):
        raise ModelFileError(f"array Aobs{m}: outcome index out of range (0..{num_obs - 1}, -1 for free)")
    if np.any(cnt < 0) or np.any(prior < 0) or np.any((obs < 0) & (cnt != 0)):
        raise ModelFileError(f"arrays Acnt{m}/Aprior{m}: negative counts or counts in free slots")
    ok = obs >= 0
    s_idx = np.nonzero(ok)[0]
    return SparseLikelihood.from_counts(prior, (num_obs, obs[ok], s_idx, cnt[ok]), capacity=max(cap, n, 1))


def _check(arr: np.ndarray, shape: tuple, name: str) -> np.ndarray:
    if arr.shape != tuple(shape):
        raise ModelFileError(f"array {name}: shape {arr.shape}, expected {tuple(shape)}")
    if arr.dtype.kind == "f" and not np.all(np.isfinite(arr)):
        raise ModelFileError(f"array {name}: contains NaN or infinite entries")
    return arr


def _check_normalised(model: Model) -> None:
    for m in range(len(model.modalities)):
        if model.is_sparse_A(m):
            if np.any(model.A[m].total() <= 0):
                raise ModelFileError(f"likelihood '{model.modalities[m].name}': a column has no positive count")
            continue
        a = model.live_A(m)
        if a.size and not np.allclose(a.sum(axis=0), 1.0, atol=1e-6):
            raise ModelFileError(f"likelihood '{model.modalities[m].name}': columns not normalised")
    for f in range(len(model.factors)):
        n = model.num_states[f]
        B = model.B[f]
        sums = B.prob[:n].sum(axis=2) if isinstance(B, SparseTransitions) else B.to_dense(n).sum(axis=0)
        if sums.size and not np.allclose(sums, 1.0, atol=1e-6):
            raise ModelFileError(f"transitions '{model.factors[f].name}': columns not normalised")

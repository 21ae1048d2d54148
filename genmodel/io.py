"""Save and load models as ``<stem>.npz`` (arrays) + ``<stem>.json`` (structure). No pickle.

The JSON records factors, modalities, live sizes, dependencies and settings, the SHA-256 of the
npz file and (from format version 3) the SHA-256 of its own other content, so a truncated,
corrupt, edited or mismatched pair is refused with a clear error. :func:`load` bounds every
size and array before allocating it, reads only regular files, and rebuilds the model through
:func:`~cogmap.genmodel.compile.compile`, so a loaded model passes every check a compiled one
does (finite, non-negative, normalised A/B/D, successor indices in range, pose shapes, names).
"""

from __future__ import annotations

import hashlib
import json
import zipfile
from dataclasses import asdict, replace
from pathlib import Path

import numpy as np

from .compile import MAX_ENTRIES, check_entries
from .compile import compile as compile_spec
from .files import regular_file_size
from .model import Model
from .spec import Factor, InductiveSpec, Modality, ModelSpec, PoseSpec, SparseA, SparseB, SpecError
from .transitions import SparseTransitions

FORMAT = "cogmap-model"
#: 3: the JSON carries the digest of its own content; 2: sparse likelihoods (SparseA) saved as
#: their counts; version 1 and 2 files still load (without the JSON digest)
VERSION = 3
READABLE = (1, 2, 3)
MAX_JSON_BYTES = 64 * 2**20  # a model description is a few kB; refuse anything absurd before reading


class ModelFileError(SpecError):
    """A saved model is missing, truncated, corrupt or inconsistent."""


def _paths(path) -> tuple[Path, Path]:
    p = Path(path)
    stem = p.with_suffix("") if p.suffix in (".npz", ".json") else p
    return stem.with_suffix(".npz"), stem.with_suffix(".json")


def _sha256_file(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def json_digest(meta: dict) -> str:
    """SHA-256 of the description without its own digest (canonical JSON: sorted keys)."""
    body = {k: v for k, v in meta.items() if k != "json_sha256"}
    return hashlib.sha256(json.dumps(body, sort_keys=True).encode()).hexdigest()


def write_files(npz_path: Path, json_path: Path, arrays: dict[str, np.ndarray], meta: dict) -> None:
    """Write ``arrays`` and ``meta`` with both digests filled in (``meta`` is updated)."""
    npz_path.parent.mkdir(parents=True, exist_ok=True)
    with open(npz_path, "wb") as fh:
        np.savez_compressed(fh, **arrays)
    meta["npz_sha256"] = _sha256_file(npz_path)
    meta["arrays"] = sorted(arrays)
    meta["json_sha256"] = json_digest(meta)
    json_path.write_text(json.dumps(meta, indent=1))


def save(model: Model, path) -> tuple[Path, Path]:
    """Write the model; returns the (npz, json) paths. Arrays are saved at live sizes."""
    npz_path, json_path = _paths(path)
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
    }
    write_files(npz_path, json_path, arrays, meta)
    return npz_path, json_path


def _read_headers(npz_path: Path, max_entries: int) -> None:
    """Check every array's declared shape and type in the archive before decompressing any."""
    try:
        with zipfile.ZipFile(npz_path) as zf:
            for info in zf.infolist():
                with zf.open(info) as fh:
                    version = np.lib.format.read_magic(fh)
                    if version == (1, 0):
                        shape, _, dtype = np.lib.format.read_array_header_1_0(fh)
                    else:
                        shape, _, dtype = np.lib.format.read_array_header_2_0(fh)
                name = info.filename.removesuffix(".npy")
                if dtype.hasobject or dtype.kind not in "biuf":
                    raise ModelFileError(f"{npz_path}: array {name} has type {dtype} (expected numbers)")
                try:
                    check_entries(shape, f"array {name}", "or check the file", max_entries)
                except SpecError as err:
                    raise ModelFileError(f"{npz_path}: {err}") from None
    except (zipfile.BadZipFile, ValueError, OSError, EOFError) as err:
        raise ModelFileError(f"{npz_path}: unreadable array archive ({err})") from None


def load(path, max_entries: int = MAX_ENTRIES) -> Model:
    """Read a model written by :func:`save`; raises :class:`ModelFileError` on any damage.

    ``max_entries`` bounds every array (in the file and at the declared capacities) before it
    is allocated, as in :func:`~cogmap.genmodel.compile.compile`."""
    npz_path, json_path = _paths(path)
    sizes = {p: regular_file_size(p, ModelFileError) for p in (npz_path, json_path)}
    if sizes[json_path] > MAX_JSON_BYTES:
        raise ModelFileError(f"{json_path}: {sizes[json_path]} bytes, too large for a model description")
    try:
        meta = json.loads(json_path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as err:
        raise ModelFileError(f"{json_path}: not valid JSON ({err})") from None
    if not isinstance(meta, dict) or meta.get("format") != FORMAT:
        raise ModelFileError(f"{json_path}: not a cogmap model description")
    if meta.get("version") not in READABLE:
        raise ModelFileError(f"{json_path}: format version {meta.get('version')} is not supported "
                             f"(this cogmap reads versions {', '.join(map(str, READABLE))})")
    if meta["version"] >= 3 and meta.get("json_sha256") != json_digest(meta):
        raise ModelFileError(f"{json_path}: edited or corrupt (its content does not match its digest)")
    _check_fields(meta, json_path)
    if _sha256_file(npz_path) != meta.get("npz_sha256"):
        raise ModelFileError(f"{npz_path}: contents do not match {json_path.name} (truncated or corrupt)")
    try:
        layout = _layout(meta, max_entries)
    except (KeyError, TypeError, IndexError, ValueError, AttributeError) as err:
        if isinstance(err, SpecError):
            raise ModelFileError(f"{json_path}: {err}") from None
        raise ModelFileError(f"{json_path}: inconsistent model description ({type(err).__name__}: {err})") from None
    _read_headers(npz_path, max_entries)
    try:
        with np.load(npz_path, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
    except (zipfile.BadZipFile, ValueError, OSError, EOFError) as err:
        raise ModelFileError(f"{npz_path}: unreadable array archive ({err})") from None
    missing = set(meta["arrays"]) - set(arrays)
    if missing:
        raise ModelFileError(f"{npz_path}: missing arrays {sorted(missing)}")
    try:
        return _rebuild(meta, layout, arrays, max_entries)
    except ModelFileError:
        raise
    except SpecError as err:
        raise ModelFileError(f"{json_path.with_suffix('')}: {err}") from None
    except (KeyError, TypeError, IndexError, ValueError) as err:
        raise ModelFileError(f"{json_path}: inconsistent model description ({type(err).__name__}: {err})") from None


#: every field of a model description: (JSON types accepted, what the message says is expected);
#: ``sparse_A`` may be missing (version 1 files)
_FIELDS = {
    "factors": ((list,), "a list of factor objects"),
    "modalities": ((list,), "a list of modality objects"),
    "num_states": ((list,), "a list of integers"),
    "num_obs": ((list,), "a list of integers"),
    "capacities": ((list,), "a list of integers"),
    "obs_capacities": ((list,), "a list of integers"),
    "A_deps": ((list,), "a list of lists of factor indices"),
    "sparse": ((list,), "a list of true/false, one per factor"),
    "sparse_A": ((list,), "a list of true/false, one per modality"),
    "arrays": ((list,), "a list of array names"),
    "npz_sha256": ((str,), "the SHA-256 of the npz file"),
    "prior_count": ((int, float), "a positive finite number"),
    "collision_preference": ((int, float, type(None)), "a finite number or null"),
    "inductive": ((dict, type(None)), "an object or null"),
    "pose": ((dict, type(None)), "an object or null"),
}
_POSE_FIELDS = {"factor": ((int,), "a factor index"), "step": ((int, float), "a number"),
                "influence_radius": ((int, float), "a number"), "sigma": ((int, float, type(None)), "a number or null")}


def _check_fields(meta: dict, json_path: Path) -> None:
    """Every field of the description present (``sparse_A`` from version 2) and of its JSON type,
    the entries of its lists too, before anything is built from them."""
    def bad(key: str, expected: str, got) -> ModelFileError:
        return ModelFileError(f"{json_path}: field {key!r}: expected {expected}, got {json.dumps(got)[:80]}")

    def typed(value, types) -> bool:
        return isinstance(value, types) and not (isinstance(value, bool) and bool not in types)

    for key, (types, expected) in _FIELDS.items():
        if key not in meta:
            if key == "sparse_A" and meta.get("version") == 1:
                continue
            raise ModelFileError(f"{json_path}: missing field {key!r} ({expected})")
        if not typed(meta[key], types):
            raise bad(key, expected, meta[key])
    for key in ("factors", "modalities"):
        for i, entry in enumerate(meta[key]):
            if not isinstance(entry, dict):
                raise bad(f"{key}[{i}]", "an object", entry)
    for i, deps in enumerate(meta["A_deps"]):
        if not isinstance(deps, list) or not all(typed(d, (int,)) for d in deps):
            raise bad(f"A_deps[{i}]", "a list of factor indices", deps)
    for key in ("sparse", "sparse_A"):
        if key in meta and not all(isinstance(v, bool) for v in meta[key]):
            raise bad(key, _FIELDS[key][1], meta[key])
    if not all(isinstance(n, str) for n in meta["arrays"]):
        raise bad("arrays", _FIELDS["arrays"][1], meta["arrays"])
    if meta["pose"] is not None:
        for key, (types, expected) in _POSE_FIELDS.items():
            if key not in meta["pose"]:
                raise ModelFileError(f"{json_path}: field 'pose': missing {key!r} ({expected})")
            if not typed(meta["pose"][key], types):
                raise bad(f"pose.{key}", expected, meta["pose"][key])
    F, M = len(meta["factors"]), len(meta["modalities"])
    for key, n in (("sparse", F), ("sparse_A", M), ("A_deps", M)):
        if key in meta and len(meta[key]) != n:
            raise ModelFileError(f"{json_path}: field {key!r}: {len(meta[key])} entries for "
                                 f"{n} {'factors' if key == 'sparse' else 'modalities'}")


def _int_list(meta: dict, key: str, length: int, minimum: int) -> list[int]:
    v = meta[key]
    if not isinstance(v, list) or len(v) != length:
        raise ModelFileError(f"'{key}' must be a list of {length} integers")
    for x in v:
        if isinstance(x, bool) or not isinstance(x, int) or x < minimum:
            raise ModelFileError(f"'{key}' must hold integers >= {minimum}, got {x!r}")
    return v


def _layout(meta: dict, max_entries: int) -> dict:
    """Factors, modalities, sizes and capacities of the description, checked and bounded
    before anything is allocated."""
    factors = tuple(
        Factor(**{**f, "control_names": None if f["control_names"] is None else tuple(f["control_names"]),
                  **({"depends_on": tuple(f["depends_on"])} if f.get("depends_on") is not None else {})})
        for f in meta["factors"]
    )
    modalities = tuple(Modality(**{**m, "depends_on": tuple(m["depends_on"])}) for m in meta["modalities"])
    F, M = len(factors), len(modalities)
    ns = _int_list(meta, "num_states", F, 1)
    no = _int_list(meta, "num_obs", M, 1)
    caps = _int_list(meta, "capacities", F, 1)
    ocaps = _int_list(meta, "obs_capacities", M, 1)
    for key, sizes, cap in (("capacities", ns, caps), ("obs_capacities", no, ocaps)):
        for i, (n, c) in enumerate(zip(sizes, cap, strict=True)):
            if c < n:
                raise ModelFileError(f"'{key}'[{i}] = {c} is smaller than the live size {n}")
    names = [f.name for f in factors]
    deps = meta["A_deps"]
    for m, mod in enumerate(modalities):
        if not isinstance(mod.depends_on, tuple) or any(d not in names for d in mod.depends_on):
            raise ModelFileError(f"modality '{mod.name}': depends on {list(mod.depends_on)}, "
                                 f"not all among the factors {names}")
        if list(deps[m]) != [names.index(d) for d in mod.depends_on]:
            raise ModelFileError(f"A_deps[{m}] = {deps[m]} does not match modality '{mod.name}' "
                                 f"depending on {list(mod.depends_on)}")
    sparse = meta["sparse"]
    sparse_A = meta.get("sparse_A", [False] * M)
    for m, mod in enumerate(modalities):
        check_entries((ocaps[m],), f"C['{mod.name}']", "lower the modality's capacity", max_entries)
        if not sparse_A[m]:
            shape = (ocaps[m],) + tuple(caps[names.index(d)] for d in mod.depends_on)
            check_entries(shape, f"A['{mod.name}']", "or give a SparseA", max_entries)
    for f, fac in enumerate(factors):
        if not sparse[f]:
            check_entries((caps[f], caps[f], fac.num_controls), f"B['{fac.name}']", "or give a SparseB", max_entries)
        else:
            check_entries((caps[f], fac.num_controls), f"B['{fac.name}']", "or fewer states", max_entries)
    return {"factors": factors, "modalities": modalities, "ns": ns, "no": no, "caps": caps, "ocaps": ocaps,
            "sparse": sparse, "sparse_A": sparse_A}


def _rebuild(meta: dict, layout: dict, arrays: dict[str, np.ndarray], max_entries: int) -> Model:
    """Turn the arrays back into a :class:`ModelSpec` at the saved live sizes and capacities and
    compile it (every check of ``compile``), then restore the factors as they were declared."""
    factors, modalities = layout["factors"], layout["modalities"]
    ns, no, caps, ocaps = layout["ns"], layout["no"], layout["caps"], layout["ocaps"]
    spec_factors = [replace(fac, size=ns[f], capacity=caps[f]) for f, fac in enumerate(factors)]
    spec_mods = [replace(mod, size=no[m], capacity=ocaps[m]) for m, mod in enumerate(modalities)]
    A, pA, B, pB, C, D, Cs = {}, {}, {}, {}, {}, {}, {}
    for m, mod in enumerate(modalities):
        C[mod.name] = arrays[f"C{m}"]
        if layout["sparse_A"][m]:
            A[mod.name] = _sparse_A(arrays, m)
            continue
        A[mod.name] = arrays[f"A{m}"]
        if f"pA{m}" in arrays:
            pA[mod.name] = arrays[f"pA{m}"]
    for f, fac in enumerate(factors):
        if layout["sparse"][f]:
            succ = arrays[f"Bsucc{f}"]
            if succ.dtype.kind not in "iu":
                raise ModelFileError(f"array Bsucc{f}: successor indices must be integers, got {succ.dtype}")
            B[fac.name] = SparseB(succ, arrays[f"Bprob{f}"], arrays.get(f"Bcounts{f}"))
        else:
            B[fac.name] = arrays[f"B{f}"]
            if f"pB{f}" in arrays:
                pB[fac.name] = arrays[f"pB{f}"]
        D[fac.name] = arrays[f"D{f}"]
        Cs[fac.name] = arrays[f"Cs{f}"]
    pose = None
    if meta["pose"] is not None:
        pm = meta["pose"]
        pf = pm["factor"]
        if isinstance(pf, bool) or not isinstance(pf, int) or not 0 <= pf < len(factors):
            raise ModelFileError(f"pose: factor index {pf!r} out of range")
        pose = PoseSpec(factors[pf].name, arrays["poses"], arrays["headings"], pm["step"], pm["influence_radius"],
                        pm["sigma"])
    spec = ModelSpec(spec_factors, spec_mods, A=A, B=B, C=C, D=D, pA=pA, pB=pB, C_states=Cs, pose=pose,
                     inductive=None if meta["inductive"] is None else InductiveSpec(**meta["inductive"]),
                     collision_preference=meta["collision_preference"])
    model = compile_spec(spec, prior_count=meta["prior_count"], max_entries=max_entries)
    model.factors, model.modalities = tuple(factors), tuple(modalities)
    return model


def _sparse_A(arrays: dict, m: int) -> SparseA:
    """A sparse likelihood's slots as a :class:`SparseA` (free slots hold -1 and no count)."""
    obs, cnt, prior = arrays[f"Aobs{m}"], arrays[f"Acnt{m}"], arrays[f"Aprior{m}"]
    if obs.ndim != 2 or obs.dtype.kind not in "iu" or cnt.shape != obs.shape:
        raise ModelFileError(f"arrays Aobs{m}/Acnt{m}: shapes {obs.shape}/{cnt.shape} ({obs.dtype}), "
                             "expected integer outcomes and counts of one (states, slots) shape")
    if obs.size and obs.min() < -1:
        raise ModelFileError(f"array Aobs{m}: outcome index {int(obs.min())} (free slots hold -1)")
    if np.any((obs < 0) & (cnt != 0)):
        raise ModelFileError(f"arrays Aobs{m}/Acnt{m}: counts in free slots")
    ok = obs >= 0
    return SparseA(prior=prior, outcomes=obs[ok], states=np.nonzero(ok)[0], counts=cnt[ok])

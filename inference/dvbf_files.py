"""A DVBF-LM model on disk: ``model.npz`` (every array leaf by its pytree path) and ``model.json``
(the configuration and the leaf names), written by :func:`save_params` and read back, checked, by
:func:`load_params`."""

from __future__ import annotations

import json
import shutil
from dataclasses import asdict
from pathlib import Path

import numpy as np

from cogmap.genmodel.dvbf import DVBFConfig


def save_params(params, cfg: DVBFConfig, out: Path) -> None:
    """``model.npz`` (every array leaf, by its pytree path) and ``model.json`` (config and leaf names).

    Parameters
    ----------
    params : DVBFParams
        q(M) and the emission network.
    cfg : DVBFConfig
        The model they belong to (written to ``model.json`` so :func:`load_params` can rebuild them).
    out : pathlib.Path
        Existing directory to write the two files into.
    """
    import equinox as eqx
    import jax

    leaves = jax.tree_util.tree_leaves_with_path(eqx.filter(params, eqx.is_array))
    arrays = {_array_name(path): np.asarray(v) for path, v in leaves}
    np.savez_compressed(out / "model.npz", **arrays)
    (out / "model.json").write_text(json.dumps({"config": asdict(cfg), "arrays": sorted(arrays)}, indent=1))


def save_emission_once(emission, cfg: DVBFConfig, out: Path) -> None:
    """Store an emission network as the model directory ``out`` (with a fresh q(M)), atomically: it
    is written to a new folder beside ``out`` and renamed, so a reader sees all of it or nothing, and
    when another process stored it first its copy is kept.

    Parameters
    ----------
    emission : object
        The emission network.
    cfg : DVBFConfig
        Its model.
    out : pathlib.Path
        The model directory to create.
    """
    import tempfile

    import jax

    from .elbo import init_params

    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(dir=out.parent))
    save_params(init_params(cfg, jax.random.PRNGKey(0))._replace(emission=emission), cfg, tmp)
    try:
        tmp.rename(out)
    except OSError:  # another process wrote it first
        shutil.rmtree(tmp, ignore_errors=True)


#: largest ``model.json`` of a DVBF-LM run (it holds the configuration and the array names: a few kB)
MAX_MODEL_JSON_BYTES = 1 << 20


class DVBFModelError(ValueError):
    """A DVBF-LM model directory (``model.json`` + ``model.npz``) that cannot be used; the message
    names the file, the field or array, and the problem."""


def _array_name(path) -> str:
    import jax

    return jax.tree_util.keystr(path).strip(".").replace("[", "_").replace("]", "").replace(".", "/")


def _read_config(json_path: Path) -> DVBFConfig:
    """The configuration in ``model.json``, every field checked (:class:`DVBFConfig` bounds the sizes)."""
    from dataclasses import fields

    from cogmap.genmodel.files import regular_file_size

    regular_file_size(json_path, DVBFModelError, MAX_MODEL_JSON_BYTES, "MAX_MODEL_JSON_BYTES")
    try:
        meta = json.loads(json_path.read_text())
    except (UnicodeDecodeError, json.JSONDecodeError) as err:
        raise DVBFModelError(f"{json_path}: not valid JSON ({err})") from None
    if not isinstance(meta, dict) or not isinstance(meta.get("config"), dict):
        raise DVBFModelError(f"{json_path}: expected an object with a 'config' object (a DVBF-LM model description)")
    c = dict(meta["config"])
    unknown = sorted(set(c) - {f.name for f in fields(DVBFConfig)})
    if unknown:
        raise DVBFModelError(f"{json_path}: config: unknown field(s) {', '.join(map(repr, unknown))}")
    for key in ("sigma_t", "radii"):
        if key in c:
            if not isinstance(c[key], list):
                raise DVBFModelError(f"{json_path}: config.{key}: expected a list of numbers, got {c[key]!r}")
            c[key] = tuple(c[key])
    try:
        return DVBFConfig(**c)
    except (TypeError, ValueError) as err:
        raise DVBFModelError(f"{json_path}: config: {err}") from None


def _read_headers(npz_path: Path) -> dict:
    """Shape and dtype of every member of the archive, read from the headers (nothing decompressed)."""
    import zipfile

    out = {}
    try:
        with zipfile.ZipFile(npz_path) as zf:
            for info in zf.infolist():
                with zf.open(info) as fh:
                    version = np.lib.format.read_magic(fh)
                    read = np.lib.format.read_array_header_1_0 if version == (1, 0) else \
                        np.lib.format.read_array_header_2_0
                    shape, _, dtype = read(fh)
                out[info.filename.removesuffix(".npy")] = (tuple(shape), dtype)
    except (zipfile.BadZipFile, ValueError, OSError, EOFError) as err:
        raise DVBFModelError(f"{npz_path}: unreadable array archive ({err})") from None
    return out


def load_params(out: Path):
    """Rebuild the parameters written by :func:`save_params`, refusing a damaged or forged model.

    The structure comes from a fresh ``init_params(cfg, ...)`` of the stored configuration (whose
    sizes :class:`~cogmap.genmodel.dvbf.DVBFConfig` bounds); every array leaf is then replaced by
    the stored array of the same pytree path, after its shape (from the archive's header, before
    decompressing) and its values (finite numbers) are checked.

    Parameters
    ----------
    out : pathlib.Path
        Directory holding ``model.npz`` and ``model.json``.

    Returns
    -------
    params : DVBFParams
        The stored q(M) and emission network.
    cfg : DVBFConfig
        The stored model configuration.

    Raises
    ------
    DVBFModelError
        (a ``ValueError``) If either file is missing or unreadable, the configuration has an
        unknown field or a value out of its range, or an array is missing, unexpected, of another
        shape than the configuration implies, not numeric or not finite; the message names it.
    """
    import equinox as eqx
    import jax

    from .elbo import init_params

    out = Path(out)
    cfg = _read_config(out / "model.json")
    template = init_params(cfg, jax.random.PRNGKey(0))
    arr, static = eqx.partition(template, eqx.is_array)
    paths = jax.tree_util.tree_leaves_with_path(arr)
    expected = {_array_name(p): tuple(v.shape) for p, v in paths}
    dtypes = [v.dtype for _, v in paths]
    npz_path = out / "model.npz"
    if not npz_path.is_file():
        raise DVBFModelError(f"{npz_path}: file not found")
    headers = _read_headers(npz_path)
    for name, shape in expected.items():
        if name not in headers:
            raise DVBFModelError(f"{npz_path}: missing array {name!r} (the configuration in model.json needs it)")
        got, dtype = headers[name]
        if dtype.hasobject or dtype.kind not in "iuf":
            raise DVBFModelError(f"{npz_path}: array {name!r} has type {dtype} (expected numbers)")
        if got != shape:
            raise DVBFModelError(f"{npz_path}: array {name!r} has shape {got}, expected {shape} from the "
                                 f"configuration in model.json")
    extra = sorted(set(headers) - set(expected))
    if extra:
        raise DVBFModelError(f"{npz_path}: unexpected array {extra[0]!r} (not part of this model)")
    new_leaves = []
    with np.load(npz_path, allow_pickle=False) as data:
        for name, dtype in zip(expected, dtypes, strict=True):
            a = data[name]
            if not np.all(np.isfinite(a)):
                raise DVBFModelError(f"{npz_path}: array {name!r} has non-finite entries (NaN or infinite)")
            new_leaves.append(jax.numpy.asarray(a, dtype=dtype))
    arr = jax.tree_util.tree_unflatten(jax.tree_util.tree_structure(arr), new_leaves)
    return eqx.combine(arr, static), cfg

"""Checkpoints of a running exploration, in JSON + npz (no pickle), so ``cogmap explore --resume``
continues where a run stopped.

A checkpoint is a directory holding

- ``model.npz`` + ``model.json``: the generative model in its own save format
  (:mod:`cogmap.genmodel.io`, digests and every check of ``load`` included);
- ``state.json``: everything else the run needs (the agent's beliefs, pose frame, counters and RNG
  state, its view map and encoder, the end-of-exploration rule, the simulator's pose, odometry and
  RNG, the episode so far and the coverage record) as a tree of plain JSON values;
- ``arrays.npz``: the arrays that tree refers to (loaded with ``allow_pickle=False``).

The tree is written by a small codec: numbers, strings, lists, tuples, dicts (any hashable keys),
sets, numpy scalars and arrays, numpy generators (their bit-generator state) and instances of
cogmap's own classes (dataclasses, named tuples and plain objects: their fields). Shared references
stay shared (an object met twice is written once and referred to), so, e.g., the odometry and the
simulator keep one generator. On reading, only classes defined in ``cogmap`` are rebuilt (their
``__init__`` is not called) and nothing is executed; anything else (a function, a foreign object)
is refused when the checkpoint is written, naming where it sits.
"""

from __future__ import annotations

import dataclasses
import functools
import importlib
import json
import shutil
import types
from pathlib import Path

import numpy as np

STATE, ARRAYS, MODEL = "state.json", "arrays.npz", "model"
ALLOWED_MODULES = ("cogmap.",)


class CheckpointError(ValueError):
    """A state that cannot be written, or a checkpoint that cannot be read."""


def _class_path(cls) -> str:
    return f"{cls.__module__}:{cls.__qualname__}"


def _lookup(path: str):
    module, _, qual = path.partition(":")
    if not module.startswith(ALLOWED_MODULES):
        raise CheckpointError(f"checkpoint refers to {path}, outside cogmap (refused)")
    obj = importlib.import_module(module)
    try:
        for part in qual.split("."):
            obj = getattr(obj, part)
    except AttributeError:
        return None
    return obj


def _resolve(path: str, kind=type):
    obj = _lookup(path)
    if not isinstance(obj, kind):
        raise CheckpointError(f"checkpoint refers to {path}, which is not a {kind.__name__}")
    return obj


class _Writer:
    def __init__(self, directory: Path):
        self.dir = directory
        self.arrays: dict[str, np.ndarray] = {}
        self.memo: dict[int, int] = {}
        self.keep: list = []  # keeps encoded objects alive so their ids stay unique
        self.models = 0

    def _ref(self, obj):
        key = id(obj)
        if key in self.memo:
            return {"$ref": self.memo[key]}, None
        n = len(self.memo)
        self.memo[key] = n
        self.keep.append(obj)
        return None, n

    def encode(self, obj, where: str):
        from cogmap.genmodel.io import save
        from cogmap.genmodel.model import Model

        if obj is None or isinstance(obj, bool | int | float | str):
            return obj
        if isinstance(obj, np.generic):
            if obj.dtype.kind not in "biuf":
                raise CheckpointError(f"{where}: numpy scalar of dtype {obj.dtype} cannot be checkpointed")
            return {"$np": obj.dtype.str, "v": obj.item()}
        ref, n = self._ref(obj)
        if ref is not None:
            return ref
        if isinstance(obj, np.ndarray):
            if obj.dtype.kind not in "biufU":
                raise CheckpointError(f"{where}: array of dtype {obj.dtype} cannot be checkpointed")
            key = f"a{len(self.arrays)}"
            self.arrays[key] = obj
            return {"$id": n, "$array": key}
        if isinstance(obj, Model):
            name = MODEL if self.models == 0 else f"{MODEL}{self.models}"
            self.models += 1
            save(obj, self.dir / name)
            return {"$id": n, "$model": name}
        if isinstance(obj, np.random.Generator):
            return {"$id": n, "$rng": self.encode(obj.bit_generator.state, where)}
        if isinstance(obj, list):
            return {"$id": n, "$list": [self.encode(v, f"{where}[{i}]") for i, v in enumerate(obj)]}
        if isinstance(obj, tuple) and not hasattr(obj, "_fields"):
            return {"$id": n, "$tuple": [self.encode(v, f"{where}[{i}]") for i, v in enumerate(obj)]}
        if isinstance(obj, set | frozenset):
            tag = "$set" if isinstance(obj, set) else "$frozenset"
            return {"$id": n, tag: [self.encode(v, f"{where}{{}}") for v in obj]}
        if isinstance(obj, dict):
            return {"$id": n, "$dict": [[self.encode(k, f"{where} key"), self.encode(v, f"{where}[{k!r}]")]
                                        for k, v in obj.items()]}
        if isinstance(obj, functools.partial):
            return {"$id": n, "$partial": [self.encode(obj.func, f"{where}.func"), self.encode(obj.args, f"{where}"),
                                           self.encode(obj.keywords, f"{where}")]}
        if isinstance(obj, types.FunctionType | types.BuiltinFunctionType):
            path = f"{obj.__module__}:{obj.__qualname__}"
            if not (obj.__module__ or "").startswith(ALLOWED_MODULES) or _lookup(path) is not obj:
                raise CheckpointError(f"{where}: function {path} cannot be checkpointed (not a module-level "
                                      f"cogmap function)")
            return {"$id": n, "$function": path}
        cls = type(obj)
        if not cls.__module__.startswith(ALLOWED_MODULES):
            raise CheckpointError(f"{where}: {_class_path(cls)} cannot be checkpointed (not a cogmap class)")
        if hasattr(obj, "_fields"):  # a named tuple
            return {"$id": n, "$tuple": [self.encode(v, f"{where}.{f}") for f, v in zip(obj._fields, obj, strict=True)],
                    "$class": _class_path(cls)}
        if dataclasses.is_dataclass(obj):
            fields = {f.name: getattr(obj, f.name) for f in dataclasses.fields(obj)}
            fields.update(getattr(obj, "__dict__", {}))
        elif hasattr(obj, "__dict__"):
            fields = dict(vars(obj))
        else:
            raise CheckpointError(f"{where}: {_class_path(cls)} has no fields to checkpoint")
        return {"$id": n, "$class": _class_path(cls),
                "$fields": {k: self.encode(v, f"{where}.{k}") for k, v in fields.items()}}


class _Reader:
    def __init__(self, directory: Path, arrays):
        self.dir, self.arrays, self.memo = directory, arrays, {}

    def decode(self, node):
        if not isinstance(node, dict):
            if isinstance(node, list):
                raise CheckpointError("malformed checkpoint: bare list")
            return node
        if "$ref" in node:
            return self.memo[node["$ref"]]
        if "$np" in node:
            return np.dtype(node["$np"]).type(node["v"])
        n = node.get("$id")
        if "$array" in node:
            out = np.array(self.arrays[node["$array"]])
        elif "$model" in node:
            from cogmap.genmodel.io import load

            out = load(self.dir / node["$model"])
        elif "$rng" in node:
            state = self.decode(node["$rng"])
            bit = getattr(np.random, state["bit_generator"])()
            bit.state = state
            out = np.random.Generator(bit)
        elif "$list" in node:
            out = []
            self.memo[n] = out
            out.extend(self.decode(v) for v in node["$list"])
        elif "$set" in node or "$frozenset" in node:
            items = [self.decode(v) for v in node.get("$set", node.get("$frozenset"))]
            out = set(items) if "$set" in node else frozenset(items)
        elif "$dict" in node:
            out = {}
            self.memo[n] = out
            for k, v in node["$dict"]:
                out[self.decode(k)] = self.decode(v)
        elif "$tuple" in node:
            items = [self.decode(v) for v in node["$tuple"]]
            out = _resolve(node["$class"])(*items) if "$class" in node else tuple(items)
        elif "$function" in node:
            out = _resolve(node["$function"], types.FunctionType)
        elif "$partial" in node:
            fn, args, kw = (self.decode(v) for v in node["$partial"])
            out = functools.partial(fn, *args, **kw)
        elif "$fields" in node:
            cls = _resolve(node["$class"])
            out = cls.__new__(cls)
            self.memo[n] = out
            for k, v in node["$fields"].items():
                object.__setattr__(out, k, self.decode(v))
        else:
            raise CheckpointError(f"malformed checkpoint node with keys {sorted(node)}")
        self.memo[n] = out
        return out


def save_checkpoint(directory: Path, state: dict) -> Path:
    """Write ``state`` as a checkpoint directory, atomically.

    The checkpoint is written to ``<directory>.new`` first; the previous checkpoint is moved to
    ``<directory>.old`` and removed only once the new one is in place, so a write cut short
    leaves a complete checkpoint behind (:func:`find_checkpoint`).

    Parameters
    ----------
    directory : pathlib.Path
        Checkpoint directory (created, or replaced when it exists).
    state : dict
        Named parts (string keys) of the state; each value is written with the codec of the
        module docstring (plain values, containers, numpy scalars and arrays of bool, integer,
        float or string dtype, generators, models, module-level cogmap functions and instances of
        cogmap classes).

    Returns
    -------
    pathlib.Path
        ``directory``.

    Raises
    ------
    CheckpointError
        When a value cannot be written (a foreign object, a lambda, an unsupported dtype), naming
        where it sits in ``state``.
    """
    directory = Path(directory)
    tmp = directory.with_name(directory.name + ".new")
    if tmp.exists():
        shutil.rmtree(tmp)
    tmp.mkdir(parents=True)
    w = _Writer(tmp)
    tree = {k: w.encode(v, k) for k, v in state.items()}
    np.savez(tmp / ARRAYS, **w.arrays)
    (tmp / STATE).write_text(json.dumps(tree))
    old = directory.with_name(directory.name + ".old")
    if directory.exists():
        if old.exists():
            shutil.rmtree(old)
        directory.rename(old)
    tmp.rename(directory)
    if old.exists():
        shutil.rmtree(old)
    return directory


def find_checkpoint(directory: Path) -> Path | None:
    """The complete checkpoint at ``directory`` (or the previous one, if a write was cut short).

    Parameters
    ----------
    directory : pathlib.Path
        Checkpoint directory as given to :func:`save_checkpoint`.

    Returns
    -------
    pathlib.Path or None
        ``directory`` when it holds ``state.json`` and ``arrays.npz``, else ``<directory>.old``
        when that does, else None.
    """
    directory = Path(directory)
    for d in (directory, directory.with_name(directory.name + ".old")):
        if (d / STATE).is_file() and (d / ARRAYS).is_file():
            return d
    return None


def load_checkpoint(directory: Path) -> dict:
    """The state written by :func:`save_checkpoint`.

    Only classes and functions defined in ``cogmap`` are rebuilt (instances without calling their
    ``__init__``); shared references are shared again; nothing is unpickled.

    Parameters
    ----------
    directory : pathlib.Path
        A complete checkpoint directory (see :func:`find_checkpoint`).

    Returns
    -------
    dict
        The named parts, as they were saved.

    Raises
    ------
    CheckpointError
        When ``state.json`` or ``arrays.npz`` cannot be read, the tree is malformed, or it refers
        to a class or function outside cogmap. The model's own loader
        (:func:`cogmap.genmodel.io.load`) raises its own errors on a damaged model.
    """
    directory = Path(directory)
    try:
        tree = json.loads((directory / STATE).read_text())
        with np.load(directory / ARRAYS, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
    except (OSError, ValueError) as err:
        raise CheckpointError(f"{directory}: unreadable checkpoint ({err})") from None
    r = _Reader(directory, arrays)
    return {k: r.decode(v) for k, v in tree.items()}

"""Checkpoints of a running exploration, in JSON + npz (no pickle), so ``cogmap explore --resume``
continues where a run stopped.

A checkpoint is a directory holding

- ``model.npz`` + ``model.json``: the generative model in its own save format
  (:mod:`cogmap.genmodel.io`, digests and every check of ``load`` included);
- ``state.json``: everything else the run needs (the agent's beliefs, pose frame, counters and RNG
  state, its view map and encoder, the end-of-exploration rule, the simulator's pose, odometry and
  RNG, the episode so far and the coverage record) as a tree of plain JSON values;
- ``arrays.npz``: the arrays that tree refers to (read by :func:`cogmap.genmodel.npzfile.read_npz`,
  which bounds every array by the bytes the file holds before allocating it).

Both are written and read with one explicit schema, :func:`exploration_schema` (:mod:`cogmap.schema`):
each field of each part has a declared type and range, and the file never names a class or a
function; what is built on reading is fixed by the schema. A state the schema does not describe
(an encoder registered by a user, a new attribute) is refused when the checkpoint is written,
naming where it sits, and the run goes on without checkpoints. The planner's per-decision summary
(``Decision.efe``, diagnostics only) is not kept: a resumed agent's last decision has an empty one.
"""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

from cogmap.genmodel.npzfile import NpzError, read_npz

from . import schema as s

STATE, ARRAYS, MODEL = "state.json", "arrays.npz", "model"
#: largest ``state.json`` read, bytes (a checkpoint of a 10,000-state map is a few MB)
MAX_STATE_BYTES = 256 << 20
#: largest total size of the arrays of ``arrays.npz``, bytes
MAX_ARRAY_BYTES = 8 << 30


class CheckpointError(ValueError):
    """A state that cannot be written, or a checkpoint that cannot be read."""


class ModelFile(s.Field):
    """A :class:`~cogmap.genmodel.Model`, saved beside ``state.json`` in its own format."""

    shared = True
    NAME = re.compile(r"model[0-9]{0,3}")

    @property
    def pytype(self):
        """:class:`~cogmap.genmodel.Model` (imported on first use)."""
        from cogmap.genmodel.model import Model

        return Model

    def write(self, value, w, where):
        from cogmap.genmodel.io import save

        if not isinstance(value, self.pytype):
            raise s.SchemaError(f"{where}: expected a Model, got {type(value).__name__}")
        n = w.extra.setdefault("models", 0)
        w.extra["models"] = n + 1
        name = MODEL if n == 0 else f"{MODEL}{n}"
        save(value, w.extra["dir"] / name)
        return name

    def read(self, node, r, where):
        from cogmap.genmodel.io import load

        if not (isinstance(node, str) and self.NAME.fullmatch(node)):
            raise s.SchemaError(f"{where}: expected a model file name (model, model1, ...), got "
                                f"{str(node)[:40]!r}")
        return load(r.extra["dir"] / node)


class Struct(s.Field):
    """A dict with exactly the string keys of ``fields``, each of its own field type.

    Parameters
    ----------
    fields
        Each key and the field type of its value.
    """

    pytype = dict

    def __init__(self, fields: dict[str, s.Field]):
        self.fields = fields

    def write(self, value, w, where):
        if not isinstance(value, dict) or value.keys() != self.fields.keys():
            raise s.SchemaError(f"{where}: expected the keys {sorted(self.fields)}, got "
                                f"{sorted(value) if isinstance(value, dict) else type(value).__name__}")
        return {k: s.encode(f, value[k], w, f"{where}[{k!r}]") for k, f in self.fields.items()}

    def read(self, node, r, where):
        if not isinstance(node, dict) or node.keys() != self.fields.keys():
            raise s.SchemaError(f"{where}: expected the keys {sorted(self.fields)}")
        return {k: s.decode(f, node[k], r, f"{where}[{k!r}]") for k, f in self.fields.items()}


class Scalar(s.Field):
    """One cell of a trajectory row: null, a boolean, an integer, a float (NaN allowed) or a string."""

    pytype = (type(None), bool, int, float, str)

    def write(self, value, w, where):
        import numpy as np

        if value is None or isinstance(value, bool | int | float | str):
            return value
        if isinstance(value, np.bool_ | np.integer | np.floating):
            return value.item()
        raise s.SchemaError(f"{where}: {type(value).__name__} is not a plain value")

    def read(self, node, r, where):
        if node is None or isinstance(node, bool | int | float):
            return node
        if isinstance(node, str) and len(node) <= s.MAX_STR:
            return node
        raise s.SchemaError(f"{where}: expected a plain value, got {type(node).__name__}")


def _exploration_schema() -> Struct:
    """The schema of an exploration checkpoint (built once, on first use)."""
    from cogmap.agent.aimapp import AIMAPPAgent, Decision
    from cogmap.agent.confidence import Confidence
    from cogmap.agent.config import AgentConfig
    from cogmap.agent.correction import Anchor
    from cogmap.agent.encoder import SSIMEncoder
    from cogmap.agent.exploration_end import Done
    from cogmap.agent.localisation import Belief, Counts, Memory
    from cogmap.agent.viewmap import Pursuit, ViewMap
    from cogmap.envs.robot import Odometry, OdometryNoise
    from cogmap.envs.sensors import STREAMS, FaultSchedule
    from cogmap.inference.se2 import SE2
    from cogmap.planning.sensed import SensedGrid

    from .harness import Episode

    count, index, state = s.Int(0), s.Int(-1), s.Int(0)
    fin = s.Float()
    xy = s.Array("f", 1, (2,))
    pose3 = s.Array("f", 1, (3,))
    rng = s.Generator()
    config = s.Via(AgentConfig, s.Json(), AgentConfig.to_dict, AgentConfig.from_dict)
    box = s.Optional(s.TupleOf(s.Int(), s.Int(), s.Int(), s.Int()))
    encoder = s.Record(SSIMEncoder, {
        "threshold": s.Float(-1.0, 1.0), "shortlist": s.Optional(s.Int(1)),
        "images": s.ListOf(s.Array("uif")),
        "_x": s.Optional(s.Array("f", 3)), "_mu": s.Optional(s.Array("f", 3)),
        "_mu2c1": s.Optional(s.Array("f", 3)), "_varc2": s.Optional(s.Array("f", 3)),
        "_thumbs": s.Array("f", 2), "last_scores": s.Array("f", 1)})
    confidence = s.Record(Confidence, {"dominance": s.Float(finite=False), "conflict": s.Float(finite=False),
                                       "lost_evidence": s.Float(finite=False), "confident": s.Bool()}, make="call")
    decision = s.Record(Decision, {
        "action": count, "waypoint": xy, "state": index, "target": index,
        "mode": s.Str(("explore", "goal", "relocalise", "paused")), "confidence": s.Optional(confidence),
        "expanded": count, "missing": s.VarTuple(s.Str(tuple(STREAMS)))}, drop={"efe": dict})
    grid = s.Record(SensedGrid, {"cells": s.Array("i", 2), "origin": xy, "resolution": s.Float(1e-6)}, make="call")
    views = s.Record(ViewMap, {
        "cfg": config, "grid": s.Optional(grid), "area": s.Array("f", 1), "robot": s.Optional(xy),
        "returns": s.Array("f", 2), "frontier_cache": s.DictOf(s.TupleOf(fin, fin), s.Float(finite=False)),
        "_dirty_states": box, "_dirty_frontier": box, "doubt": s.SetOf(state),
        "pursuit": s.Record(Pursuit, {"target": index, "viewpoint": s.Optional(xy), "unreached": count,
                                      "spent": s.ListOf(s.TupleOf(xy, fin)), "spent_at": count, "blind": s.Bool()})})
    anchor = s.Record(Anchor, {"pose": xy, "panorama": s.Array("uif"), "scan": s.Array("f", 2), "step": count})
    se2 = s.Record(SE2, {"yaw": fin, "x": fin, "y": fin}, make="call")
    belief = s.Record(Belief, {"q": s.Array("f", 1), "frame": se2, "lost": s.Bool(),
                               "lost_evidence": s.Float(finite=False), "last_obs": s.Optional(state),
                               "outcome": s.Optional(s.Bool())}, make="call")
    counts = s.Record(Counts, {k: count for k in Counts._fields}, make="call")
    memory = s.Record(Memory, {
        "anchors": s.DictOf(state, anchor), "scanned": s.SetOf(state),
        "traversed": s.SetOf(s.TupleOf(state, state, state)), "frame_moves": s.ListOf(Struct({
            "step": count, "kind": s.Str(("correction", "relocalisation")), "moved_m": s.Float(0.0)})),
        "views": views}, make="call")
    agent = s.Record(AIMAPPAgent, {
        "cfg": config, "encoder": encoder, "rng": rng, "model": ModelFile(), "belief": belief, "counts": counts,
        "memory": memory, "last": s.Optional(decision), "goal_obs": s.Optional(state)})
    done = s.Record(Done, {"agent": agent, "patience": count, "quiet": count, "seen": s.TupleOf(count, count),
                           "seen_all": count, "rule": s.Str(tuple(Done.RULES)), "loop_factor": count,
                           "pursuing": s.Bool()})
    episode = s.Record(Episode, {"rows": s.ListOf(s.DictOf(s.Str(max_len=100), Scalar())),
                                 "coverage": s.ListOf(s.Float(0.0, 1.0)), "distance": s.ListOf(s.Float(0.0)),
                                 "decision_ms": s.ListOf(s.Float(0.0)), "num_states": s.ListOf(count)})
    noise = s.Record(OdometryNoise, {k: s.Float(0.0) if k != "heading_bias" else fin
                                     for k in ("slip", "heading_bias", "trans_std", "rot_std")}, make="call")
    sim = Struct({
        "pose": pose3, "odom": s.Record(Odometry, {"noise": noise, "pose": pose3, "rng": rng,
                                                   "travelled": s.Float(0.0)}),
        "rng": rng, "step_count": count, "path": s.ListOf(pose3), "odom_path": s.ListOf(pose3),
        "scheduled": s.ListOf(s.TupleOf(count, s.Str(max_len=200), s.VarTuple(fin), s.Optional(fin))),
        "faults": s.Record(FaultSchedule, {"windows": s.DictOf(s.Str(tuple(STREAMS)),
                                                               s.ListOf(s.TupleOf(count, count)))})})
    return Struct({"agent": agent, "done": done, "episode": episode, "moved": s.Optional(s.Bool()),
                   "distance": s.Optional(s.Float(0.0)), "coverage_seen": s.Array("b", 2), "sim": sim})


_SCHEMA: list[Struct] = []


def exploration_schema() -> Struct:
    """The schema of an exploration checkpoint: its parts ``agent``, ``done``, ``episode``,
    ``moved``, ``distance``, ``coverage_seen`` and ``sim``, and every field of each.

    Returns
    -------
    Struct
        The schema (built once, on first use).
    """
    if not _SCHEMA:
        _SCHEMA.append(_exploration_schema())
    return _SCHEMA[0]


def save_checkpoint(directory: Path, state: dict, schema: s.Field | None = None) -> Path:
    """Write ``state`` as a checkpoint directory, atomically.

    The checkpoint is written to ``<directory>.new`` first; the previous checkpoint is moved to
    ``<directory>.old`` and removed only once the new one is in place, so a write cut short
    leaves a complete checkpoint behind (:func:`find_checkpoint`).

    Parameters
    ----------
    directory : pathlib.Path
        Checkpoint directory (created, or replaced when it exists).
    state : dict
        The state, as ``schema`` describes it.
    schema : cogmap.schema.Field, optional
        Its schema, default :func:`exploration_schema`.

    Returns
    -------
    pathlib.Path
        ``directory``.

    Raises
    ------
    CheckpointError
        When a value does not fit the schema (an object it does not describe, a value out of
        range), naming where it sits in ``state``; nothing is left at ``directory`` then but the
        previous checkpoint.
    """
    directory = Path(directory)
    schema = schema or exploration_schema()
    tmp = directory.with_name(directory.name + ".new")
    if tmp.exists():
        shutil.rmtree(tmp)
    tmp.mkdir(parents=True)
    w = s.Writer()
    w.extra["dir"] = tmp
    try:
        tree = s.encode(schema, state, w, "state")
    except s.SchemaError as err:
        shutil.rmtree(tmp, ignore_errors=True)
        raise CheckpointError(str(err)) from None
    import numpy as np

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


def load_checkpoint(directory: Path, schema: s.Field | None = None) -> dict:
    """The state written by :func:`save_checkpoint`, read with the same schema.

    Every field is checked against its declared type and range; shared references are shared
    again; nothing is unpickled and nothing in the file chooses what is built.

    Parameters
    ----------
    directory : pathlib.Path
        A complete checkpoint directory (see :func:`find_checkpoint`).
    schema : cogmap.schema.Field, optional
        Its schema, default :func:`exploration_schema`.

    Returns
    -------
    dict
        The state, as it was saved.

    Raises
    ------
    CheckpointError
        When ``state.json`` or ``arrays.npz`` cannot be read or exceed :data:`MAX_STATE_BYTES` /
        :data:`MAX_ARRAY_BYTES`, or a field does not fit the schema (the message names it). The
        model's own loader (:func:`cogmap.genmodel.io.load`) raises its own errors on a damaged
        model.
    """
    directory = Path(directory)
    schema = schema or exploration_schema()
    try:
        size = (directory / STATE).stat().st_size
        if size > MAX_STATE_BYTES:
            raise CheckpointError(f"{directory / STATE}: {size} bytes, more than the limit of {MAX_STATE_BYTES}")
        tree = json.loads((directory / STATE).read_text())
        arrays = read_npz(directory / ARRAYS, kinds="biuf", max_bytes=MAX_ARRAY_BYTES)
    except (OSError, ValueError, RecursionError) as err:
        if isinstance(err, CheckpointError):
            raise
        msg = str(err) if isinstance(err, NpzError) else f"{directory}: unreadable checkpoint ({err})"
        raise CheckpointError(msg) from None
    r = s.Reader(arrays, dir=directory)
    try:
        return s.decode(schema, tree, r, "state")
    except s.SchemaError as err:
        raise CheckpointError(f"{directory / STATE}: {err}") from None

"""Checkpoints: written and read by an explicit schema (no class named by the file), shared
references kept, generators continue, every field's type and range checked on reading."""

from __future__ import annotations

import json
import zipfile

import numpy as np
import pytest

from cogmap import schema as s
from cogmap.checkpoint import CheckpointError, ModelFile, Struct, load_checkpoint, save_checkpoint
from cogmap.envs.robot import OdometryNoise
from cogmap.inference.se2 import SE2

NOISE = s.Record(OdometryNoise, {k: s.Float() for k in ("slip", "heading_bias", "trans_std", "rot_std")},
                 make="call")
SCHEMA = Struct({
    "rng": s.Generator(), "again": s.Generator(), "arr": s.Array("f", 2), "view": s.Array("f", 2),
    "tuple": s.TupleOf(s.Int(), s.Str(), s.Optional(s.Int())), "set": s.SetOf(s.Int(0, 9)),
    "keys": s.DictOf(s.TupleOf(s.Int(), s.Int()), s.Str()), "frame": s.Record(SE2, {
        "yaw": s.Float(), "x": s.Float(), "y": s.Float()}, make="call"),
    "noise": NOISE, "flag": s.Bool(), "model": ModelFile(), "nan": s.Float(finite=False),
    "steps": s.Int(0, 100)})


def _state():
    from cogmap.genmodel.demo_models import tmaze

    rng = np.random.default_rng(5)
    rng.normal(size=3)
    arr = np.arange(6.0).reshape(2, 3)
    return {"rng": rng, "again": rng, "arr": arr, "view": arr, "tuple": (1, "x", None), "set": {3, 4},
            "keys": {(1, 2): "pair"}, "frame": SE2(0.3, 1.0, -2.0), "noise": OdometryNoise(slip=0.05),
            "flag": True, "model": tmaze(), "nan": float("nan"), "steps": 7}


def test_round_trip_keeps_values_types_and_shared_references(tmp_path):
    state = _state()
    save_checkpoint(tmp_path / "ck", state, SCHEMA)
    assert not (tmp_path / "ck.new").exists()
    got = load_checkpoint(tmp_path / "ck", SCHEMA)
    assert got["rng"] is got["again"] and got["arr"] is got["view"]
    assert got["rng"].normal(size=4).tolist() == state["rng"].normal(size=4).tolist()  # the generator continues
    assert got["tuple"] == (1, "x", None) and got["set"] == {3, 4} and got["keys"] == {(1, 2): "pair"}
    assert got["frame"] == SE2(0.3, 1.0, -2.0) and isinstance(got["frame"], SE2)
    assert got["noise"] == OdometryNoise(slip=0.05) and got["flag"] is True and got["steps"] == 7
    assert np.array_equal(got["arr"], state["arr"]) and np.isnan(got["nan"])
    assert (tmp_path / "ck" / "model.npz").exists()  # the model in its own save format
    assert all(np.array_equal(x.prob, y.prob) for x, y in zip(got["model"].A, state["model"].A, strict=True))
    text = (tmp_path / "ck" / "state.json").read_text()
    assert "$class" not in text and "OdometryNoise" not in text and "numpy" not in text  # no type named


def test_a_state_the_schema_does_not_describe_is_refused_naming_where_it_sits(tmp_path):
    state = _state()
    state["noise"] = SE2(0.0, 0.0, 0.0)
    with pytest.raises(CheckpointError, match=r"state\['noise'\]: .*SE2 has no checkpoint schema"):
        save_checkpoint(tmp_path / "ck", state, SCHEMA)
    state = _state()
    state["steps"] = 101
    with pytest.raises(CheckpointError, match=r"state\['steps'\]: 101 is outside \[0, 100\]"):
        save_checkpoint(tmp_path / "ck", state, SCHEMA)
    assert not (tmp_path / "ck").exists() and not (tmp_path / "ck.new").exists()


@pytest.mark.parametrize("edit, message", [
    (lambda t: t.update(steps=-5), r"state\['steps'\]: -5 is outside \[0, 100\]"),
    (lambda t: t.update(steps=True), r"state\['steps'\]: expected an integer, got boolean True"),
    (lambda t: t["frame"]["v"].update(x="1"), r"state\['frame'\].x: expected a number, got string '1'"),
    (lambda t: t["frame"]["v"].update(x=float("inf")), r"state\['frame'\].x: inf is not a finite number"),
    (lambda t: t["frame"]["v"].update(z=0.0), r"SE2 with unknown field\(s\) \['z'\]"),
    (lambda t: t.update(again={"$ref": 99}), r"state\['again'\]: reference to an object not read before"),
    (lambda t: t.update(model="../../etc/passwd"), r"state\['model'\]: expected a model file name"),
])
def test_a_field_of_the_wrong_type_or_range_is_refused_naming_it(tmp_path, edit, message):
    save_checkpoint(tmp_path / "ck", _state(), SCHEMA)
    path = tmp_path / "ck" / "state.json"
    tree = json.loads(path.read_text())
    edit(tree)
    path.write_text(json.dumps(tree))
    with pytest.raises(CheckpointError, match=message):
        load_checkpoint(tmp_path / "ck", SCHEMA)


def test_an_array_whose_header_declares_more_than_the_file_holds_is_refused_before_allocating(tmp_path):
    save_checkpoint(tmp_path / "ck", _state(), SCHEMA)
    npz = tmp_path / "ck" / "arrays.npz"
    with zipfile.ZipFile(npz) as z:
        names = z.namelist()
    header = "{'descr': '<f8', 'fortran_order': False, 'shape': (100000, 100000, 1000), }"
    raw = b"\x93NUMPY\x01\x00" + len(header.ljust(118) + "\n").to_bytes(2, "little") + (
        header.ljust(118) + "\n").encode()
    with zipfile.ZipFile(npz, "w") as z:
        for name in names:
            z.writestr(name, raw)
    declared = r"array .a0. declares shape \(100000, 100000, 1000\) \(80000000000000 bytes\) but the archive holds"
    with pytest.raises(CheckpointError, match=declared):
        load_checkpoint(tmp_path / "ck", SCHEMA)


# -- the payload of a class-naming decoder, against a real exploration checkpoint ------------------


@pytest.fixture(scope="module")
def exploration_checkpoint(tmp_path_factory):
    """The checkpoint an exploration of the house stopped after 3 decisions leaves (of decision 2)."""
    from unittest import mock

    from cogmap.explore import Done, explore

    out = tmp_path_factory.mktemp("explore") / "run"
    real = Done.__call__

    def ctrl_c(self, decision):
        ended = real(self, decision)
        if self.agent.counts.steps == 3:  # after the checkpoint of decision 2
            raise KeyboardInterrupt
        return ended

    with mock.patch.object(Done, "__call__", ctrl_c), pytest.raises(KeyboardInterrupt):
        explore("house", steps=20, seed=0, out=out, progress=False, patience=0, checkpoint_every=2)
    assert load_checkpoint(out / "checkpoint")["agent"].counts.steps == 2
    return out / "checkpoint"


def _places(tree, path=()):
    """Every position of a JSON tree (dict values and list items), as key paths."""
    yield path
    items = tree.items() if isinstance(tree, dict) else enumerate(tree) if isinstance(tree, list) else ()
    for k, v in items:
        yield from _places(v, (*path, k))


def _put(tree, path, value):
    if not path:
        return value
    node = tree
    for k in path[:-1]:
        node = node[k]
    node[path[-1]] = value
    return tree


PAYLOADS = [
    lambda marker: {"$class": "cogmap.runs:subprocess.Popen", "$tuple": [["touch", marker]]},
    lambda marker: {"$class": "subprocess:Popen", "$args": [["touch", marker]], "$kwargs": {}},
    lambda marker: {"$class": "cogmap.checkpoint:shutil.rmtree", "$tuple": [marker]},
    lambda marker: {"$class": "os:system", "$tuple": [f"touch {marker}"]},
    lambda marker: {"$id": 0, "v": {"$class": "builtins:eval", "$tuple": [f"open({marker!r}, 'w')"]}},
]


@pytest.mark.parametrize("payload", range(len(PAYLOADS)))
def test_a_class_naming_payload_anywhere_in_state_json_is_refused_and_runs_nothing(
        tmp_path, exploration_checkpoint, payload):
    import shutil

    ck = tmp_path / "checkpoint"
    shutil.copytree(exploration_checkpoint, ck)
    marker = str(tmp_path / "ran")
    original = json.loads((ck / "state.json").read_text())
    places = list(_places(original))
    # the root, every part, and a spread of nested places (records, lists, generators, arrays)
    chosen = places[:1] + [p for p in places if len(p) == 1] + places[1::max(1, len(places) // 40)]
    for place in chosen:
        tree = _put(json.loads(json.dumps(original)), place, PAYLOADS[payload](marker))
        (ck / "state.json").write_text(json.dumps(tree))
        with pytest.raises(CheckpointError) as err:
            load_checkpoint(ck)
        assert "\n" not in str(err.value) and "state.json: state" in str(err.value), (place, str(err.value))
    assert len(chosen) > 30
    assert not (tmp_path / "ran").exists()  # nothing was run


def test_the_exploration_checkpoint_round_trips(tmp_path, exploration_checkpoint):
    state = load_checkpoint(exploration_checkpoint)
    save_checkpoint(tmp_path / "again", state)
    again = load_checkpoint(tmp_path / "again")
    assert again["done"].agent is again["agent"] and again["sim"]["odom"].rng is again["sim"]["rng"]
    assert json.loads((tmp_path / "again" / "state.json").read_text()) == json.loads(
        (exploration_checkpoint / "state.json").read_text())

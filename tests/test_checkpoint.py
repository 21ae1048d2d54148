"""The checkpoint codec: JSON + npz, shared references kept, generators continue, only cogmap classes."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from cogmap.checkpoint import CheckpointError, load_checkpoint, save_checkpoint
from cogmap.envs.robot import OdometryNoise
from cogmap.inference.se2 import SE2


def test_round_trip_keeps_values_types_and_shared_references(tmp_path):
    from cogmap.genmodel.demo_models import tmaze

    rng = np.random.default_rng(5)
    rng.normal(size=3)
    shared = [1, 2]
    arr = np.arange(6.0).reshape(2, 3)
    model = tmaze()
    state = {"a": {"rng": rng, "again": rng, "list": shared, "same": shared, "arr": arr, "view": arr,
                   "tuple": (1, "x", None), "set": {3, 4}, "keys": {(1, 2): "pair", 7: np.float32(0.5)},
                   "frame": SE2(0.3, 1.0, -2.0), "noise": OdometryNoise(slip=0.05), "flag": np.bool_(True),
                   "model": model, "nan": float("nan")}}
    save_checkpoint(tmp_path / "ck", state)
    assert not (tmp_path / "ck.new").exists()
    got = load_checkpoint(tmp_path / "ck")["a"]
    assert got["rng"] is got["again"] and got["list"] is got["same"] and got["arr"] is got["view"]
    assert got["rng"].normal(size=4).tolist() == rng.normal(size=4).tolist()  # the generator continues
    assert got["tuple"] == (1, "x", None) and got["set"] == {3, 4}
    assert got["keys"] == {(1, 2): "pair", 7: np.float32(0.5)} and type(got["keys"][7]) is np.float32
    assert got["frame"] == SE2(0.3, 1.0, -2.0) and isinstance(got["frame"], SE2)
    assert got["noise"] == OdometryNoise(slip=0.05) and type(got["flag"]) is np.bool_
    assert np.array_equal(got["arr"], arr) and np.isnan(got["nan"])
    assert (tmp_path / "ck" / "model.npz").exists()  # the model in its own save format
    assert all(np.array_equal(x.prob, y.prob) for x, y in zip(got["model"].A, model.A, strict=True))


def test_foreign_objects_are_refused_naming_where_they_sit(tmp_path):
    with pytest.raises(CheckpointError, match=r"agent\['where'\]\[1\]: pathlib:PosixPath cannot be checkpointed"):
        save_checkpoint(tmp_path / "ck", {"agent": {"where": [0, Path("/tmp")]}})
    with pytest.raises(CheckpointError, match="function .*<lambda> cannot be checkpointed"):
        save_checkpoint(tmp_path / "ck", {"f": lambda: 0})


def test_a_checkpoint_naming_a_class_outside_cogmap_is_refused(tmp_path):
    save_checkpoint(tmp_path / "ck", {"noise": OdometryNoise()})
    state = json.loads((tmp_path / "ck" / "state.json").read_text())
    state["noise"]["$class"] = "subprocess:Popen"
    (tmp_path / "ck" / "state.json").write_text(json.dumps(state))
    with pytest.raises(CheckpointError, match="refers to subprocess:Popen, outside cogmap"):
        load_checkpoint(tmp_path / "ck")

"""Save/load round-trips exactly; damaged files give a clear ModelFileError."""

import json

import numpy as np
import pytest

from cogmap.genmodel import Factor, Modality, ModelSpec, PoseSpec, compile, normalise
from cogmap.genmodel.io import ModelFileError, load, save
from cogmap.genmodel.transitions import SparseTransitions
from cogmap.inference.learning import Event, learn_transition


def grown_model():
    rng = np.random.default_rng(3)
    B = np.stack([np.eye(2), np.eye(2)[::-1]], axis=-1)
    pA = rng.random((3, 2)) + 0.5
    spec = ModelSpec(
        factors=[Factor("s", 2, num_controls=2, growable=True, stay=0)],
        modalities=[Modality("o", 3, ("s",), growable=True)],
        A={"o": normalise(pA)},
        pA={"o": pA},
        B={"s": B},
        pB={"s": B * 2},
        C={"o": np.array([0.0, 2.0, -1.0])},
        pose=PoseSpec("s", rng.random((2, 2)), headings=[0.3]),
    )
    model = compile(spec)
    for i in range(5):
        model.add_state("s", pose=(i, -i))
    model.add_observation("o")
    learn_transition(model, 0, 2, 1, 3, Event.POSSIBLE, reverse_control=1)
    return model


def sparse_model():
    model = grown_model()
    model.B[0] = SparseTransitions.from_dense(model.B[0].prob, counts=model.B[0].counts)
    return model


def _assert_same(a, b):
    assert a.num_states == b.num_states and a.num_obs == b.num_obs
    assert a.factors == b.factors and a.modalities == b.modalities
    for m in range(len(a.modalities)):
        np.testing.assert_array_equal(a.live_A(m), b.live_A(m))
        np.testing.assert_array_equal(a.live_pA(m), b.live_pA(m))
        np.testing.assert_array_equal(a.live_C(m), b.live_C(m))
    for f in range(len(a.factors)):
        np.testing.assert_array_equal(a.live_B(f), b.live_B(f))
        np.testing.assert_array_equal(a.live_pB(f), b.live_pB(f))
        np.testing.assert_array_equal(a.live_D(f), b.live_D(f))
    np.testing.assert_array_equal(a.pose.poses[: a.num_states[0]], b.pose.poses[: b.num_states[0]])


@pytest.mark.parametrize("make", [grown_model, sparse_model])
def test_round_trip_exact_and_growth_continues(tmp_path, make):
    model = make()
    save(model, tmp_path / "m")
    back = load(tmp_path / "m.json")
    _assert_same(model, back)
    back.add_state("s", pose=(9, 9))  # a loaded model keeps growing
    assert back.num_states[0] == model.num_states[0] + 1


def test_truncated_npz(tmp_path):
    npz, _ = save(grown_model(), tmp_path / "m")
    data = npz.read_bytes()
    npz.write_bytes(data[: len(data) // 2])
    with pytest.raises(ModelFileError, match="truncated or corrupt"):
        load(tmp_path / "m")


def test_corrupt_json_and_missing_file(tmp_path):
    _, js = save(grown_model(), tmp_path / "m")
    js.write_text(js.read_text()[:-20])
    with pytest.raises(ModelFileError, match="not valid JSON"):
        load(tmp_path / "m")
    with pytest.raises(ModelFileError, match="file not found"):
        load(tmp_path / "absent")


def test_inconsistent_description(tmp_path):
    from cogmap.genmodel.io import write_files

    npz, js = save(grown_model(), tmp_path / "m")
    meta = json.loads(js.read_text())
    meta["num_states"] = [3]
    with np.load(npz) as z:
        arrays = {k: z[k] for k in z.files}
    write_files(npz, js, arrays, meta)  # digests valid, content inconsistent
    with pytest.raises(ModelFileError, match=r"A\['o'\]: shape \(4, 7\), expected \(4, 3\)"):
        load(tmp_path / "m")


def test_no_pickle_in_archive(tmp_path):
    npz, _ = save(grown_model(), tmp_path / "m")
    with np.load(npz, allow_pickle=False) as z:
        assert all(z[k].dtype != object for k in z.files)

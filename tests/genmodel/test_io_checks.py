"""load() refuses what compile() refuses, bounds sizes before allocating, reads only regular
files, and notices an edited description. Files are forged with valid digests (as a buggy
writer would produce them) so that the content checks themselves are exercised."""

import json
import os

import numpy as np
import pytest

from cogmap.genmodel import Factor, Modality, ModelSpec, SpecError, compile
from cogmap.genmodel.io import ModelFileError, json_digest, load, save, write_files

from .test_io import grown_model, sparse_model


def forge(tmp_path, model, arrays_edit=None, meta_edit=None, version=None):
    npz, js = save(model, tmp_path / "m")
    meta = json.loads(js.read_text())
    with np.load(npz) as z:
        arrays = {k: z[k] for k in z.files}
    if arrays_edit:
        arrays_edit(arrays)
    if meta_edit:
        meta_edit(meta)
    write_files(npz, js, arrays, meta)
    if version is not None:  # an older format: no digest of the description
        meta = json.loads(js.read_text())
        meta["version"] = version
        del meta["json_sha256"]
        if version == 1:
            del meta["sparse_A"]
        js.write_text(json.dumps(meta))
    return tmp_path / "m"


def _set(name, index, value):
    def edit(arrays):
        arrays[name] = arrays[name].copy()
        arrays[name][index] = value
    return edit


def _rename_factor(meta):
    meta["factors"][0]["name"] = "renamed"


def _pose_shape(arrays):
    arrays["poses"] = arrays["poses"][:, :1]


CONTENT = {
    "negative prior count": (grown_model, _set("pB0", (0, 0, 0), -1.0), None, "pB['s']: contains negative entries"),
    "NaN prior count": (grown_model, _set("pA0", (0, 0), np.nan), None, "pA['o']: contains NaN or infinite"),
    "negative likelihood": (grown_model, _set("A0", (0, 0), -0.5), None, "A['o']: contains negative entries"),
    "unnormalised likelihood": (grown_model, _set("A0", (0, 0), 0.9), None, "A['o']: column (0,) sums to"),
    "unnormalised D": (grown_model, _set("D0", 0, 0.9), None, "D['s']: sums to"),
    "NaN preference": (grown_model, _set("C0", 0, np.nan), None, "C['o']: contains NaN or infinite"),
    "successor out of range": (sparse_model, _set("Bsucc0", (1, 1, 0), 99), None,
                               "B['s']: successor indices must be integers in [0, 7)"),
    "renamed factor": (grown_model, None, _rename_factor, "modality 'o': depends on ['s'], not all among"),
    "pose array shape": (grown_model, _pose_shape, None, "pose: poses must be finite with shape (7, 2)"),
    "live size beyond capacity": (grown_model, None, lambda m: m.update(num_states=[9]), "is smaller than the live"),
    "huge capacity": (grown_model, None, lambda m: m.update(capacities=[10**6]),
                      "B['s']: capacity shape (1000000, 1000000, 2) needs 2e+12 entries"),
    "string size": (grown_model, None, lambda m: m.update(num_obs=["4"]), "'num_obs' must hold integers"),
}


@pytest.mark.parametrize("case", sorted(CONTENT))
@pytest.mark.parametrize("version", [None, 2])
def test_load_runs_the_compile_checks(tmp_path, case, version):
    make, arrays_edit, meta_edit, message = CONTENT[case]
    path = forge(tmp_path, make(), arrays_edit, meta_edit, version)
    with pytest.raises(ModelFileError) as err:
        load(path)
    assert message in str(err.value)


def test_edited_description_is_refused(tmp_path):
    _, js = save(grown_model(), tmp_path / "m")
    meta = json.loads(js.read_text())
    meta["prior_count"] = 5.0
    js.write_text(json.dumps(meta, indent=1))
    with pytest.raises(ModelFileError, match="edited or corrupt"):
        load(tmp_path / "m")
    meta["json_sha256"] = json_digest(meta)  # re-signed: accepted, with the new value
    js.write_text(json.dumps(meta))
    assert load(tmp_path / "m").prior_count == 5.0


@pytest.mark.parametrize("version", [1, 2])
@pytest.mark.parametrize("make", [grown_model, sparse_model])
def test_older_format_versions_still_load(tmp_path, version, make):
    model = make()
    back = load(forge(tmp_path, model, version=version))
    np.testing.assert_array_equal(back.live_B(0), model.live_B(0))
    np.testing.assert_array_equal(back.live_pA(0), model.live_pA(0))
    assert back.factors == model.factors and back.num_states == model.num_states


def test_arrays_in_the_archive_are_bounded_before_reading(tmp_path):
    spec = ModelSpec([Factor("s", 2)], [Modality("o", 2, ("s",))], A={"o": np.eye(2)}, B={"s": np.eye(2)[..., None]})
    path = forge(tmp_path, compile(spec), arrays_edit=lambda a: a.update(junk=np.zeros(1000)))
    with pytest.raises(ModelFileError, match=r"array junk: capacity shape \(1000,\) needs 1e\+03 entries"):
        load(path, max_entries=500)
    assert load(path).num_states == [2]


def test_directory_or_device_in_place_of_a_file_is_refused(tmp_path):
    npz, _ = save(grown_model(), tmp_path / "m")
    npz.unlink()
    npz.mkdir()
    with pytest.raises(ModelFileError, match=r"m\.npz: not a regular file \(a directory\)"):
        load(tmp_path / "m")
    npz.rmdir()
    os.symlink("/dev/zero", npz)
    with pytest.raises(ModelFileError, match=r"m\.npz: not a regular file \(a device, pipe or socket\)"):
        load(tmp_path / "m")


def test_huge_outcome_capacity_of_a_sparse_modality_is_bounded(tmp_path):
    from cogmap.genmodel import SparseA

    spec = ModelSpec([Factor("s", 2, growable=True)], [Modality("o", 2, ("s",), growable=True)],
                     A={"o": SparseA(prior=np.ones(2))}, B={"s": np.eye(2)[..., None]})
    path = forge(tmp_path, compile(spec), meta_edit=lambda m: m.update(obs_capacities=[10**12]))
    with pytest.raises(ModelFileError, match=r"C\['o'\]: capacity shape \(1000000000000,\)"):
        load(path)
    big = ModelSpec([Factor("s", 2, growable=True)], [Modality("o", 2, ("s",), growable=True, capacity=10**12)],
                    A={"o": SparseA(prior=np.ones(2))}, B={"s": np.eye(2)[..., None]})
    with pytest.raises(SpecError, match=r"C\['o'\]: capacity shape"):
        compile(big)


def test_nan_setting_in_the_description_is_refused(tmp_path):
    path = forge(tmp_path, grown_model(), meta_edit=lambda m: m.update(prior_count=float("nan")))
    with pytest.raises(ModelFileError, match="prior_count: must be a positive finite number, got nan"):
        load(path)


def _signed(tmp_path, edit):
    """A saved model whose description is edited and signed again (as a buggy writer would)."""
    _, js = save(grown_model(), tmp_path / "m")
    meta = json.loads(js.read_text())
    edit(meta)
    meta["json_sha256"] = json_digest(meta)
    js.write_text(json.dumps(meta))
    return tmp_path / "m"


@pytest.mark.parametrize("edit, message", [
    (lambda m: m.pop("arrays"), "missing field 'arrays' (a list of array names)"),
    (lambda m: m.update(arrays=5), "field 'arrays': expected a list of array names, got 5"),
    (lambda m: m.update(arrays=["A0", 3]), "field 'arrays': expected a list of array names"),
    (lambda m: m.pop("factors"), "missing field 'factors'"),
    (lambda m: m.update(factors={"s": 1}), "field 'factors': expected a list of factor objects"),
    (lambda m: m.update(modalities=["o"]), "field 'modalities[0]': expected an object, got \"o\""),
    (lambda m: m.update(A_deps=[[0.5]]), "field 'A_deps[0]': expected a list of factor indices"),
    (lambda m: m.update(sparse=[1]), "field 'sparse': expected a list of true/false"),
    (lambda m: m.update(sparse=[False, False]), "field 'sparse': 2 entries for 1 factors"),
    (lambda m: m.update(prior_count="1"), "field 'prior_count': expected a positive finite number, got \"1\""),
    (lambda m: m.update(collision_preference=[1]), "field 'collision_preference': expected a finite number or null"),
    (lambda m: m.update(pose=3), "field 'pose': expected an object or null, got 3"),
    (lambda m: m.update(pose={"factor": 0, "step": 1.0, "influence_radius": 1.0}), "field 'pose': missing 'sigma'"),
    (lambda m: m.update(npz_sha256=None), "field 'npz_sha256': expected the SHA-256 of the npz file, got null"),
])
def test_each_field_of_the_description_is_checked_with_the_loader_error(tmp_path, edit, message):
    with pytest.raises(ModelFileError) as err:
        load(_signed(tmp_path, edit))
    assert str(err.value).startswith(f"{tmp_path / 'm.json'}: {message}"), str(err.value)

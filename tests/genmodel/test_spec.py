"""compile(): valid specs give arrays; every invalid spec gives one clear SpecError."""

import numpy as np
import pytest

from cogmap.genmodel import Factor, Modality, ModelSpec, PoseSpec, SparseB, SpecError, compile, normalise


def small_spec(**overrides):
    rng = np.random.default_rng(0)
    kw = dict(
        factors=[Factor("loc", 3, num_controls=2, stay=0), Factor("ctx", 2)],
        modalities=[Modality("see", 4, ("loc", "ctx")), Modality("cue", 2, ("ctx",))],
        A={"see": normalise(rng.random((4, 3, 2))), "cue": np.eye(2)},
        B={
            "loc": np.stack([np.eye(3), np.roll(np.eye(3), 1, axis=0)], axis=-1),
            "ctx": np.eye(2)[:, :, None],
        },
        C={"see": np.array([0.0, 1.0, 0.0, -1.0])},
        D={"ctx": np.array([0.5, 0.5])},
    )
    kw.update(overrides)
    return ModelSpec(**kw)


def test_valid_spec_compiles_to_pymdp_layout():
    model = compile(small_spec())
    assert model.A[0].prob.shape == (4, 3, 2)
    assert model.A_deps == ((0, 1), (1,))
    assert model.B[0].prob.shape == (3, 3, 2)
    np.testing.assert_allclose(model.D[0], np.full(3, 1 / 3))
    np.testing.assert_allclose(model.C[0], [0.0, 1.0, 0.0, -1.0])
    assert model.factor_names == ("loc", "ctx")


def _expect(match, **overrides):
    with pytest.raises(SpecError, match=match):
        compile(small_spec(**overrides))


def test_wrong_shape_names_modality():
    A = {"see": small_spec().A["see"], "cue": np.ones((2, 3)) / 2}
    _expect(r"A\['cue'\]: shape \(2, 3\), expected \(2, 2\)", A=A)


def test_unnormalised_column_names_factor():
    B = small_spec().B
    bad = B["loc"].copy()
    bad[0, 1, 1] += 0.5
    _expect(r"B\['loc'\]: column \(1, 1\) sums to 1.5", B={**B, "loc": bad})


def test_negative_and_nan_entries():
    A = small_spec().A
    neg = A["cue"].copy()
    neg[0, 0] = -0.1
    _expect(r"A\['cue'\]: contains negative", A={**A, "cue": neg})
    nan = A["cue"].copy()
    nan[0, 0] = np.nan
    _expect(r"A\['cue'\]: contains NaN", A={**A, "cue": nan})


def test_unknown_names_and_missing_dependencies():
    _expect(r"C\['smell'\]: unknown modality 'smell'", C={"smell": np.zeros(2)})
    _expect(r"D\['speed'\]: unknown factor 'speed'", D={"speed": np.ones(1)})
    _expect(
        r"modality 'see': depends on missing factor 'time'",
        modalities=[Modality("see", 4, ("loc", "time")), Modality("cue", 2, ("ctx",))],
    )
    _expect(r"B\['ctx'\]: missing transitions", B={"loc": small_spec().B["loc"]})
    _expect(r"A\['cue'\]: missing likelihood", A={"see": small_spec().A["see"]})


def test_stay_must_be_identity():
    B = small_spec().B
    bad = B["loc"].copy()
    bad[:, :, 0] = np.roll(np.eye(3), 1, axis=0)
    _expect(r"B\['loc'\]: stay control 0 must be the identity", B={**B, "loc": bad})


def test_bad_initial_belief_and_preferences():
    _expect(r"D\['ctx'\]: sums to 0.8", D={"ctx": np.array([0.4, 0.4])})
    _expect(r"C\['see'\]: shape \(3,\)", C={"see": np.zeros(3)})


def test_sparse_transitions_validated():
    succ = np.array([[[0], [1]], [[1], [2]], [[2], [0]]])
    prob = np.ones((3, 2, 1))
    ok = small_spec(B={"loc": SparseB(succ, prob), "ctx": np.eye(2)[:, :, None]})
    model = compile(ok)
    np.testing.assert_allclose(model.live_B(0), small_spec().B["loc"])
    bad = succ.copy()
    bad[0, 1, 0] = 7
    B = {"loc": SparseB(bad, prob), "ctx": np.eye(2)[:, :, None]}
    _expect(r"successor indices must be integers in \[0, 3\)", B=B)


def test_pose_spec_validated():
    poses = np.zeros((3, 2))
    _expect(r"pose: 1 headings expected", pose=PoseSpec("loc", poses, headings=[0.0, 1.0]))
    _expect(r"pose: poses must be finite with shape \(3, 2\)", pose=PoseSpec("loc", np.zeros((2, 2)), [0.0]))
    model = compile(small_spec(pose=PoseSpec("loc", poses, [0.0], step=0.5)))
    np.testing.assert_allclose(model.pose.predict(np.zeros(2), 1, stay=0), [0.5, 0.0])
    np.testing.assert_allclose(model.pose.predict(np.ones(2), 0, stay=0), [1.0, 1.0])


def test_duplicate_names_rejected():
    _expect(r"factor 'loc': declared twice", factors=[Factor("loc", 3, 2, stay=0), Factor("loc", 2)])

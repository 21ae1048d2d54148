"""The common call, the registry and input checking."""

import numpy as np
import pytest
from inference_helpers import random_model

from cogmap import inference
from cogmap.inference import InferenceError, InferenceInfo

SCHEMES = ("exact", "filter", "fpi", "vmp", "vmp_pymdp", "mmp")


@pytest.fixture(scope="module")
def model():
    return random_model(0, sizes=(4,), modalities=((0,), (0,)), obs_sizes=(3, 5))


def test_builtin_schemes_registered():
    assert set(SCHEMES) <= set(inference.available())
    for name in SCHEMES:
        assert callable(inference.get(name))


def test_unknown_scheme_lists_available():
    with pytest.raises(KeyError, match="available"):
        inference.get("nope")


def test_user_scheme_without_editing_package(model):
    def prior_only(model, prior, observations, actions=None, **options):
        prob = inference.prepare(model, prior, observations, actions)
        return list(prob.prior), InferenceInfo(0.0, (prob.prior,), 0)

    inference.register("toy_prior_only", prior_only)
    try:
        assert "toy_prior_only" in inference.available()
        q, info = inference.get("toy_prior_only")(model, [model.live_D(0)], [[0, 1]])
        np.testing.assert_allclose(q[0], model.live_D(0))
        with pytest.raises(ValueError, match="exists"):
            inference.register("toy_prior_only", lambda *a, **k: None)
        with pytest.raises(ValueError, match="exists"):
            inference.register("fpi", prior_only)
    finally:
        inference.unregister("toy_prior_only")
    assert "toy_prior_only" not in inference.available()


def test_register_as_decorator():
    @inference.register("toy_decorated")
    def scheme(model, prior, observations, actions=None):
        raise NotImplementedError

    try:
        assert inference.get("toy_decorated") is scheme
    finally:
        inference.unregister("toy_decorated")


@pytest.mark.parametrize("name", SCHEMES)
def test_result_shape_and_info(model, name):
    q, info = inference.get(name)(model, [model.live_D(0)], [[0, 1], [2, None]], [(1,)])
    assert isinstance(info, InferenceInfo)
    assert len(q) == 1 and q[0].shape == (4,)
    assert abs(q[0].sum() - 1) < 1e-12
    assert len(info.history) == 2 and info.iterations >= 1
    assert np.isfinite(info.free_energy)
    with pytest.raises(AttributeError):
        info.free_energy = 0.0  # frozen


@pytest.mark.parametrize("name", SCHEMES)
@pytest.mark.parametrize(
    ("prior", "obs", "actions", "match"),
    [
        ("D2", [[0, 1]], None, "factor"),  # wrong number of factors in the prior
        ([np.ones(3) / 3], [[0, 1]], None, "length 4"),  # wrong prior length
        ([np.array([0.5, 0.5, 0.5, 0.0])], [[0, 1]], None, "sums to 1.5"),  # unnormalised
        ([np.array([1.5, -0.5, 0.0, 0.0])], [[0, 1]], None, "non-negative"),
        ("D", [[0, 1, 2]], None, "3 entries, the model has 2 modalities"),
        ("D", [[0]], None, "1 entries"),
        ("D", [[3, 1]], None, "index 3 out of range"),
        ("D", [[0, -1]], None, "out of range"),
        ("D", [[0, np.ones(4) / 4]], None, "length 5"),
        ("D", [[0, np.ones(5)]], None, "sums to 5"),
        ("D", [], None, "empty"),
        ("D", [[0, 1], [0, 1]], None, "actions"),
        ("D", [[0, 1], [0, 1]], [(0,), (1,)], "T - 1 = 1"),
        ("D", [[0, 1], [0, 1]], [(2,)], "control 2 out of range"),
        ("D", [{"m0": 0, "zz": 1}], None, "unknown modality 'zz'"),
        ("D", [{"m0": 0, "pose": (0.0, 0.0)}], None, "no pose factor"),
    ],
)
def test_bad_input_errors(model, name, prior, obs, actions, match):
    if prior == "D":
        prior = [model.live_D(0)]
    elif prior == "D2":
        prior = [model.live_D(0), model.live_D(0)]
    with pytest.raises(InferenceError, match=match):
        inference.get(name)(model, prior, obs, actions)


def test_dict_and_list_observations_agree(model):
    D = [model.live_D(0)]
    a, _ = inference.exact(model, D, [[None, 4]])
    b, _ = inference.exact(model, D, [{"m1": 4}])
    c, _ = inference.exact(model, D, [{1: 4}])
    np.testing.assert_allclose(a[0], b[0])
    np.testing.assert_allclose(a[0], c[0])


def test_prior_at_capacity_length_accepted():
    m = random_model(1, sizes=(3,), growable=True)
    assert m.state_capacity(0) == 4
    full = np.zeros(4)
    full[:3] = m.live_D(0)
    q, _ = inference.bayes_filter(m, [full], [[1]])
    assert q[0].shape == (3,)
    bad = full.copy()
    bad[3] = 0.1
    bad /= bad.sum()
    with pytest.raises(InferenceError, match="beyond the 3 live"):
        inference.bayes_filter(m, [bad], [[1]])


def test_exact_joint_size_guard():
    m = random_model(2, sizes=(4, 4), modalities=((0, 1),))
    with pytest.raises(InferenceError, match="max_joint=8"):
        inference.exact(m, [m.live_D(0), m.live_D(1)], [[0]], max_joint=8)


def test_filter_refuses_multi_factor():
    m = random_model(2, sizes=(2, 2), modalities=((0,),))
    with pytest.raises(InferenceError, match="single-factor"):
        inference.bayes_filter(m, [m.live_D(0), m.live_D(1)], [[0]])


def test_zero_probability_observation_reported():
    m = random_model(3, sizes=(2,), modalities=((0,),), obs_sizes=(2,))
    m.A[0].prob[:, :] = np.array([[1.0, 1.0], [0.0, 0.0]])
    with pytest.raises(InferenceError, match="zero probability"):
        inference.exact(m, [m.live_D(0)], [[1]])


@pytest.mark.parametrize("scheme", ["exact", "filter", "fpi", "vmp", "vmp_pymdp", "mmp"])
def test_every_scheme_refuses_an_observation_of_probability_zero_as_exact_does(scheme):
    m = random_model(3, sizes=(2,), modalities=((0,),), obs_sizes=(2,))
    m.A[0].prob[:, :] = np.array([[1.0, 1.0], [0.0, 0.0]])  # outcome 1 never happens
    fn = inference.get(scheme)
    with pytest.raises(InferenceError, match=f"^{scheme}: observations up to step 0 have zero probability under "
                                             "the model$"):
        fn(m, [m.live_D(0)], [[1]])
    # possible under the prior of a later step only through B: refused at that step
    m.A[0].prob[:, :] = np.array([[1.0, 0.0], [0.0, 1.0]])  # the outcome names the state
    b = np.zeros_like(m.B[0].prob[:2, :2])
    b[0, :, :] = 1.0  # every control leads to state 0
    m.B[0].prob[:2, :2] = b
    with pytest.raises(InferenceError, match=f"^{scheme}: observations up to step 1 have zero probability"):
        fn(m, [m.live_D(0)], [[0], [1]], [(0,)])
    q, _ = fn(m, [m.live_D(0)], [[1], [0]], [(0,)])  # possible: accepted
    assert np.argmax(q[0]) == 0


def test_a_modality_that_rules_out_every_state_of_another_factor_is_refused_by_fpi():
    m = random_model(4, sizes=(2, 3), modalities=((0,), (0, 1)), obs_sizes=(2, 2))
    m.A[0].prob[:, :2] = np.array([[1.0, 0.0], [0.0, 1.0]])  # outcome 0 of the first modality: state 0
    m.A[1].prob[:, :2, :3] = 0.0
    m.A[1].prob[0, :2, :3] = 1.0
    m.A[1].prob[1, 1, :3], m.A[1].prob[0, 1, :3] = 1.0, 0.0  # outcome 1 of the second only from state 1
    prior = [m.live_D(0), m.live_D(1)]
    with pytest.raises(InferenceError, match="fpi: observations up to step 0 have zero probability"):
        inference.fpi(m, prior, [[0, 1]])
    inference.fpi(m, prior, [[1, 1]])

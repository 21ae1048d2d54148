"""Bad inputs to the inference schemes are refused, never truncated, parsed or ignored."""

import numpy as np
import pytest

from cogmap import inference
from cogmap.genmodel import Factor, Modality, ModelSpec, compile
from cogmap.inference import InferenceError


@pytest.fixture(scope="module")
def model():
    B = np.stack([np.eye(2), np.eye(2)[::-1]], -1)
    return compile(ModelSpec([Factor("s", 2, 2)], [Modality("o", 2, ("s",))],
                             A={"o": np.array([[0.9, 0.2], [0.1, 0.8]])}, B={"s": B}))


@pytest.mark.parametrize("name", ["exact", "fpi", "vmp", "vmp_pymdp", "mmp"])
@pytest.mark.parametrize("action, message", [
    (1.0, "actions[0]: expected integer control indices, got 1.0"),
    (1.7, "actions[0]: expected integer control indices, got 1.7"),
    ("1", "actions[0]: got the string '1'"),
    ((0.0,), "actions[0]: expected integer control indices"),
    (True, "actions[0]: expected integer control indices"),
])
def test_float_string_and_bool_actions_are_refused(model, name, action, message):
    with pytest.raises(InferenceError) as err:
        inference.get(name)(model, [model.live_D(0)], [0, 1], [action])
    assert message in str(err.value)


def test_integer_actions_still_work(model):
    for a in (1, np.int64(1), (1,), np.array([1])):
        q, _ = inference.get("exact")(model, [model.live_D(0)], [0, 1], [a])
        assert q[0].shape == (2,)


@pytest.mark.parametrize("name", ["fpi", "vmp", "vmp_pymdp", "mmp"])
@pytest.mark.parametrize("num_iter, message", [(0, "num_iter must be >= 1, got 0"), (-3, "must be >= 1, got -3"),
                                                (2.5, "num_iter must be an integer >= 1, got 2.5")])
def test_num_iter_below_one_or_not_an_integer_is_refused(model, name, num_iter, message):
    with pytest.raises(InferenceError) as err:
        inference.get(name)(model, [model.live_D(0)], [0], num_iter=num_iter)
    assert message in str(err.value)


def test_complex_or_string_prior_and_evidence_are_refused(model):
    exact = inference.get("exact")
    with pytest.raises(InferenceError, match="prior for factor 's': complex entries"):
        exact(model, [np.array([0.5, 0.5]) + 0j], [0])
    with pytest.raises(InferenceError, match=r"observations\[0\] for modality 'o': not a numeric array \(got strings"):
        exact(model, [model.live_D(0)], [[["0.5", "0.5"]]])

"""Dirichlet learning: closed-form updates, Table 7 rates, positive counts, normalised columns."""

import numpy as np
import pytest

from cogmap.genmodel import Factor, Modality, ModelSpec, SpecError, compile
from cogmap.genmodel.transitions import SparseTransitions
from cogmap.inference.learning import (
    TABLE7,
    Event,
    learn_observation,
    learn_transition,
    update_pA,
    update_pB,
)


def test_table7_rates():
    assert [TABLE7.rate(e) for e in Event] == [7, -7, 5, -5]
    assert [TABLE7.rate(e, reverse=True) for e in Event] == [5, -5, 3, -3]


def test_pure_updates_match_outer_products():
    rng = np.random.default_rng(0)
    pA = rng.random((3, 2, 4)) + 0.1
    q1, q2 = rng.dirichlet(np.ones(2)), rng.dirichlet(np.ones(4))
    new = update_pA(pA, 1, [q1, q2], lr=2.0)
    expected = pA.copy()
    expected[1] += 2.0 * np.outer(q1, q2)
    np.testing.assert_allclose(new, expected)
    pB = rng.random((4, 4, 2)) + 0.1
    qn, qp = rng.dirichlet(np.ones(4)), rng.dirichlet(np.ones(4))
    out = update_pB(pB, qn, qp, 1, lr=0.5)
    np.testing.assert_allclose(out[:, :, 1], pB[:, :, 1] + 0.5 * np.outer(qn, qp))
    np.testing.assert_array_equal(out[:, :, 0], pB[:, :, 0])
    floored = update_pB(pB, qn, qp, 1, lr=-100.0, floor=1e-3)
    assert floored[:, :, 1].min() == pytest.approx(1e-3)


def nav_model(sparse):
    n, u = 3, 3
    B = np.zeros((n, n, u))
    for a in range(u):
        B[:, :, a] = np.eye(n)
    spec = ModelSpec([Factor("s", n, u, growable=True, stay=0)], [Modality("o", 2, ("s",))],
                     A={"o": np.full((2, n), 0.5)}, B={"s": B}, pA={"o": np.ones((2, n))}, pB={"s": B.copy()})
    model = compile(spec)
    if sparse:
        model.B[0] = SparseTransitions.from_dense(model.B[0].prob, counts=model.B[0].counts)
    return model


@pytest.mark.parametrize("sparse", [False, True])
def test_transition_events(sparse):
    model = nav_model(sparse)
    learn_transition(model, 0, 0, 1, 1, Event.POSSIBLE, reverse_control=2)
    B = model.live_B(0)
    # self-loop prior count 1, forward +7 -> 7/8; reverse +5 -> 5/6
    assert B[1, 0, 1] == pytest.approx(7 / 8)
    assert B[0, 1, 2] == pytest.approx(5 / 6)
    learn_transition(model, 0, 0, 1, 1, Event.IMPOSSIBLE)
    B = model.live_B(0)
    # -7 on the target (floored: counts stay positive), +7 on staying in place
    assert B[1, 0, 1] == pytest.approx(1e-3 / (8 + 1e-3))
    assert B[0, 0, 1] == pytest.approx(8 / (8 + 1e-3))
    assert model.live_pB(0).min() >= 0 and model.live_pB(0)[1, 0, 1] > 0
    np.testing.assert_allclose(B.sum(axis=0), 1.0)
    learn_transition(model, 0, 0, 1, 1, Event.PREDICTED_POSSIBLE)
    assert model.live_B(0)[1, 0, 1] == pytest.approx((1e-3 + 5) / (8 + 1e-3 + 5))
    # the stay control is structural: never learned
    learn_transition(model, 0, 2, 0, 1, Event.POSSIBLE)
    np.testing.assert_array_equal(model.live_B(0)[:, :, 0], np.eye(3))
    # a column reinforced many times is capped at the maximum concentration (forgetting)
    for _ in range(10):
        learn_transition(model, 0, 1, 1, 2, Event.POSSIBLE)
    assert model.live_pB(0)[:, 1, 1].sum() == pytest.approx(TABLE7.max_concentration)
    for _ in range(3):
        learn_transition(model, 0, 1, 1, 2, Event.IMPOSSIBLE)
    assert model.live_B(0)[2, 1, 1] < 0.05  # three blocked attempts overturn it
    with pytest.raises(SpecError, match="state 5 is not live"):
        learn_transition(model, 0, 0, 1, 5, Event.POSSIBLE)


def test_observation_learning_in_place():
    model = nav_model(False)
    learn_observation(model, "o", 1, [np.array([1.0, 0.0, 0.0])], lr=3.0)
    np.testing.assert_allclose(model.live_A(0)[:, 0], [1 / 5, 4 / 5])
    np.testing.assert_allclose(model.live_A(0)[:, 1], [0.5, 0.5])

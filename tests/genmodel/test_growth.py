"""Growth keeps counts, normalisation and the structural STAY, and reallocates rarely."""

import math

import numpy as np

from cogmap.genmodel import Factor, Modality, ModelSpec, PoseSpec, SparseB, compile, normalise


def growable_model(sparse: bool, n0: int = 3):
    rng = np.random.default_rng(1)
    u = 3  # stay + two moves
    B = np.zeros((n0, n0, u))
    B[:, :, 0] = np.eye(n0)
    B[:, :, 1] = np.roll(np.eye(n0), 1, axis=0)
    B[:, :, 2] = np.roll(np.eye(n0), -1, axis=0)
    pA = rng.random((4, n0)) * 5 + 0.1
    spec = ModelSpec(
        factors=[Factor("s", n0, num_controls=u, growable=True, stay=0)],
        modalities=[Modality("o", 4, ("s",), growable=True)],
        A={"o": normalise(pA)},
        pA={"o": pA},
        B={"s": SparseB(*_to_sparse(B)) if sparse else B},
        pB={"s": B * 3.0},
        pose=PoseSpec("s", rng.random((n0, 2)), headings=[0.0, np.pi]),
    )
    return compile(spec)


def _to_sparse(B):
    n, _, u = B.shape
    succ = np.argmax(B, axis=0).T[:, :, None]  # (n, u, 1)
    return succ.astype(int), np.ones((n, u, 1))


def _check_invariants(model, pA_before, n_before):
    n = model.num_states[0]
    A = model.live_A(0)
    np.testing.assert_allclose(A.sum(axis=0), 1.0, atol=1e-12)
    B = model.live_B(0)
    np.testing.assert_allclose(B.sum(axis=0), 1.0, atol=1e-12)
    np.testing.assert_array_equal(B[:, :, 0], np.eye(n))
    # counts of the states that existed before are untouched
    np.testing.assert_array_equal(model.live_pA(0)[: pA_before.shape[0], :n_before], pA_before)


def test_thousand_add_state_calls_dense_and_sparse():
    for sparse in (False, True):
        model = growable_model(sparse)
        pA0 = model.live_pA(0).copy()
        pB0 = model.live_pB(0).copy()
        for i in range(1000):
            s = model.add_state("s", pose=(i, 0.0))
            assert s == 3 + i
        assert model.num_states[0] == 1003
        _check_invariants(model, pA0, 3)
        np.testing.assert_array_equal(model.live_pB(0)[:3, :3], pB0)
        # capacity doubled from 4 to 1024: 8 reallocations, about log2(1000)
        assert model.compile_count <= math.ceil(math.log2(1000))
        assert model.compile_count == 8
        np.testing.assert_allclose(model.pose.poses[1002], [999, 0.0])
        # new states are uniform over outcomes and self-loop under every move
        np.testing.assert_allclose(model.live_A(0)[:, 500], 0.25)
        assert model.live_B(0)[500, 500, 1] == 1.0


def test_add_observation_keeps_counts_and_normalisation():
    model = growable_model(sparse=True)
    pA0 = model.live_pA(0).copy()
    for _ in range(40):
        model.add_observation("o")
    assert model.num_obs[0] == 44
    A = model.live_A(0)
    np.testing.assert_allclose(A.sum(axis=0), 1.0, atol=1e-12)
    np.testing.assert_array_equal(model.live_pA(0)[:4], pA0)
    np.testing.assert_allclose(model.live_pA(0)[4:], model.prior_count)
    assert model.compile_count == 4  # 4 -> 8 -> 16 -> 32 -> 64


def test_growth_of_fixed_factor_is_refused():
    import pytest

    from cogmap.genmodel import SpecError

    spec = ModelSpec([Factor("s", 2)], [Modality("o", 2, ("s",))], A={"o": np.eye(2)}, B={"s": np.eye(2)[:, :, None]})
    model = compile(spec)
    with pytest.raises(SpecError, match="factor 's' is not growable"):
        model.add_state("s")
    with pytest.raises(SpecError, match="modality 'o' is not growable"):
        model.add_observation("o")
    with pytest.raises(SpecError, match="unknown factor 'x'"):
        model.add_state("x")

"""The Gaussian-kernel belief update (the "kernel" scheme) against DRONE.md 2.4."""

import numpy as np
import pytest

from cogmap import inference
from cogmap.genmodel.drone_beliefs import DRONE_FACTORS, KernelBeliefModel, entropy, expected_state
from cogmap.inference import InferenceError


def kernel(bins, obs, width, wrap=False):
    d = bins - obs
    if wrap:
        d = (d + np.pi) % (2 * np.pi) - np.pi
    L = np.exp(-0.5 * (d / width) ** 2)
    return L / L.sum()


OBS = {"distance": 40.0, "azimuth": 0.7, "elevation": -0.2, "suitability": 0.83, "density": 0.05}
WIDTHS = {"distance": 0.1 * (1 + 0.5 * 40 / 100), "azimuth": 0.2, "elevation": 0.2, "suitability": 0.1,
          "density": 0.1}


def test_bins_and_registration():
    sizes = {f.name: (f.n, f.lo, f.hi) for f in DRONE_FACTORS}
    assert sizes["distance"] == (75, 0.0, 125.0)
    assert sizes["azimuth"][0] == sizes["elevation"][0] == sizes["suitability"][0] == sizes["density"][0] == 50
    assert inference.get("kernel") is inference.kernel_filter


def test_one_update_from_uniform_is_08u_02L():
    m = KernelBeliefModel()
    u = m.uniform()
    post, info = inference.get("kernel")(m, u, [OBS])
    for f, b in zip(m.factors, post, strict=True):
        L = kernel(f.bins, OBS[f.name], WIDTHS[f.name], f.circular)
        ref = 0.8 / f.n + 0.2 * L
        if f.name == "distance":  # target weighting b *= 1 + exp(-d/10) (125 - bin)/125
            ref = ref * (1 + np.exp(-40 / 10) * (125 - f.bins) / 125)
        ref = ref / ref.sum()
        np.testing.assert_allclose(b, ref, atol=1e-12)
    assert np.isfinite(info.free_energy) and len(info.history) == 1


def test_per_call_reinitialisation_gives_064u_036L():
    m = KernelBeliefModel(target_weighting=False)
    post, _ = inference.kernel_filter(m, None, [OBS])
    for f, b in zip(m.factors, post, strict=True):
        L = kernel(f.bins, OBS[f.name], WIDTHS[f.name], f.circular)
        np.testing.assert_allclose(b, 0.64 / f.n + 0.36 * L, atol=1e-12)
    # with the distance reweighting (default) the other factors are unchanged
    post_w, _ = inference.kernel_filter(KernelBeliefModel(), None, [OBS])
    for b, c in zip(post[1:], post_w[1:], strict=True):
        np.testing.assert_allclose(b, c, atol=1e-15)
    assert not np.allclose(post[0], post_w[0])


def test_persistent_beliefs_carry_over():
    m = KernelBeliefModel(target_weighting=False)
    first, _ = inference.kernel_filter(m, None, [OBS])
    moved = {**OBS, "suitability": 0.2}
    again, _ = inference.kernel_filter(m, first, [moved])
    L = kernel(m.factors[3].bins, 0.2, 0.1)
    np.testing.assert_allclose(again[3], 0.8 * first[3] + 0.2 * L, atol=1e-12)
    fresh, _ = inference.kernel_filter(m, None, [moved])
    assert not np.allclose(fresh[3], again[3])


def test_azimuth_wraps():
    m = KernelBeliefModel()
    f = m.factors[1]
    near_pi, _ = inference.kernel_filter(m, m.uniform(), [{"azimuth": np.pi - 0.01}])
    near_minus_pi, _ = inference.kernel_filter(m, m.uniform(), [{"azimuth": -np.pi + 0.01}])
    b1 = near_pi[1]
    # mass on both ends of the bin range: the kernel wraps around +-pi
    assert b1[0] > 1.5 / f.n and b1[-1] > 1.5 / f.n and b1[1] > 1.5 / f.n
    np.testing.assert_allclose(b1, near_minus_pi[1][::-1], atol=1e-12)  # mirror images
    mean = expected_state(m, near_pi)["azimuth"]
    assert abs(abs(mean) - np.pi) < 0.2  # circular mean stays near +-pi, not 0


def test_far_distance_does_not_underflow_and_bad_input_is_named():
    m = KernelBeliefModel()
    post, _ = inference.kernel_filter(m, None, [{"distance": 140.0}])
    assert np.isfinite(post[0]).all() and np.argmax(post[0]) == 74
    with pytest.raises(InferenceError, match="unknown factor"):
        inference.kernel_filter(m, None, [{"speed": 1.0}])
    with pytest.raises(InferenceError, match="KernelBeliefModel"):
        inference.kernel_filter(object(), None, [OBS])
    with pytest.raises(InferenceError, match="distribution"):
        inference.kernel_filter(m, [np.ones(75)] + m.uniform()[1:], [OBS])


def test_entropy_reference():
    assert entropy(np.full(50, 1 / 50)) == pytest.approx(np.log(50))

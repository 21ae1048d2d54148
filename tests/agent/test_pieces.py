"""The agent's pure pieces: SSIM encoder, Eq. (7) expansion, the confidence test."""

import numpy as np
import pytest
from scipy.ndimage import gaussian_filter

from cogmap.agent.confidence import assess, conflict, dominance
from cogmap.agent.encoder import SSIMEncoder, ssim
from cogmap.agent.mapping import expansion_free_energies, expansion_free_energy
from cogmap.inference.reduction import reduce_dirichlet


def reference_ssim(a, b):
    """Wang et al. (2004) SSIM with scipy's Gaussian filter (window 11, sigma 1.5, mirror edges)."""
    g = lambda x: gaussian_filter(x, 1.5, truncate=5 / 1.5, mode="mirror")  # noqa: E731
    x, y = a.astype(float), b.astype(float)
    c1, c2 = (0.01 * 255) ** 2, (0.03 * 255) ** 2
    mx, my = g(x), g(y)
    vx, vy, cxy = g(x * x) - mx**2, g(y * y) - my**2, g(x * y) - mx * my
    return np.mean((2 * mx * my + c1) * (2 * cxy + c2) / ((mx**2 + my**2 + c1) * (vx + vy + c2)))


def panoramas(n, seed=0):
    rng = np.random.default_rng(seed)
    base = gaussian_filter(rng.random((n, 32, 128)) * 255, (0, 2, 2))
    return base.astype(np.uint8)


def test_ssim_matches_independent_reference():
    imgs = panoramas(3)
    for a, b in [(imgs[0], imgs[1]), (imgs[0], imgs[0]), (imgs[1], imgs[2])]:
        assert ssim(a, b) == pytest.approx(reference_ssim(a, b), abs=1e-4)
    assert ssim(imgs[0], imgs[0]) == pytest.approx(1.0)


def test_encoder_batches_agree_with_pairwise_and_threshold_decides():
    imgs = panoramas(260, seed=1)  # three channel batches of stored images
    enc = SSIMEncoder(threshold=0.65)
    for img in imgs:
        enc.add(img)
    query = np.clip(imgs[257].astype(int) + 3, 0, 255).astype(np.uint8)
    scores = enc.scores(query)
    for i in (0, 100, 257, 259):
        assert scores[i] == pytest.approx(ssim(query, imgs[i]), abs=1e-4)  # float32 sums
    obs, new = enc(query)
    assert (obs, new) == (257, False)
    fresh = panoramas(1, seed=99)[0]
    obs, new = enc(fresh)
    assert new and obs == 260 and len(enc) == 261


def test_expansion_follows_the_free_energy_sign():
    poses = np.array([[0.0, 0.0], [1.0, 0.0]])
    R, sigma = 1.0, 1 / 3
    inside = expansion_free_energy([1.5, 0.0], poses, R, sigma)
    beyond = expansion_free_energy([2.2, 0.0], poses, R, sigma)
    assert inside.nearest == 1 and inside.free_energy > 0 and not inside.expand
    assert beyond.free_energy < 0 and beyond.expand
    # the decision flips exactly at the influence radius
    assert not expansion_free_energy([1.99, 0.0], poses, R, sigma).expand
    assert expansion_free_energy([2.01, 0.0], poses, R, sigma).expand
    assert expansion_free_energy([5.0, 5.0], np.zeros((0, 2)), R, sigma).expand
    # the vectorised form is one Bayesian model reduction (Eq. 7) per candidate
    d = np.array([0.3, 0.99, 1.01, 2.5])
    single = []
    for x in d:
        w = np.array([np.exp(-(x**2) / (2 * sigma**2)), np.exp(-(R**2) / (2 * sigma**2))])
        current, expanded = np.array([4.0, 0.25]), np.array([0.25, 4.0])
        single.append(reduce_dirichlet(current + w / w.sum(), current, expanded).free_energy)
    np.testing.assert_allclose(expansion_free_energies(d, R, sigma), single)


def test_confidence_scores_do_not_depend_on_map_size():
    for n in (2, 3, 10, 1000):
        q = np.full(n, 1e-3 / (n - 1))
        q[0] = 1 - 1e-3
        assert dominance(q) == pytest.approx(np.log((1 - 1e-3) / (1e-3 / (n - 1))))
    q = np.array([0.999, 0.001])
    assert assess(q, q, None, 4.0).confident  # ln(999) = 6.9 nats
    assert not assess(np.array([0.9, 0.1]), q, None, 4.0).confident
    # a familiar observation strongly tied to state 1 seen where the pose allows only state 0: conflict
    A_row = np.array([0.01, 0.95])
    assert conflict(A_row, np.array([0.999, 0.001])) > 4
    assert conflict(A_row, np.array([0.001, 0.999])) < 0.1
    # the lost test is a CUSUM on conflict: one odd view does not fire it, a run of them does
    believed = np.array([0.999, 0.001])
    first = assess(believed, believed, A_row, 4.0, evidence=0.0, slack=1.0)
    assert first.confident and not first.lost(4.0)
    second = assess(believed, believed, A_row, 4.0, evidence=first.lost_evidence, slack=1.0)
    assert second.lost(4.0) and not second.confident
    calm = assess(believed, believed, np.array([0.9, 0.3]), 4.0, evidence=3.0, slack=1.0)
    assert calm.lost_evidence < 3.0  # expected observations drain the statistic


def test_shortlist_match_agrees_with_exhaustive_search():
    imgs = panoramas(80, seed=5)
    rng = np.random.default_rng(6)
    full, quick = SSIMEncoder(shortlist=None), SSIMEncoder(shortlist=8)
    for img in imgs[:60]:
        full.add(img)
        quick.add(img)
    for i in list(range(0, 60, 6)) + list(range(60, 80, 2)):  # stored places seen again, and new places
        query = np.clip(imgs[i].astype(int) + rng.integers(-6, 7, imgs[i].shape), 0, 255).astype(np.uint8)
        (b1, s1), (b2, s2) = full.match(query), quick.match(query)
        if s1 >= full.threshold:  # recognised: the shortlist finds the same stored image
            assert b1 == b2 and s1 == pytest.approx(s2, abs=1e-6)
        else:  # new place: new for both
            assert s2 < quick.threshold
        assert (s1 >= full.threshold) == (i < 60)

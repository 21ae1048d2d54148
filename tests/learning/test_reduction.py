"""Bayesian model reduction agrees with closed-form Dirichlet evidence computed independently."""

import numpy as np
import pytest
from scipy.special import gammaln

from cogmap.genmodel import SpecError
from cogmap.inference.reduction import reduce_dirichlet


def dirichlet_multinomial_log_evidence(counts, prior):
    """ln p(sequence | Dirichlet(prior)) per column, summed: direct closed form."""
    total = 0.0
    for c, a in zip(np.atleast_2d(counts.T), np.atleast_2d(prior.T), strict=True):
        total += gammaln(a.sum()) - gammaln(a.sum() + c.sum()) + np.sum(gammaln(a + c) - gammaln(a))
    return total


CASES = [
    # (prior p, alternative prior r, observed counts)
    (np.array([1.0, 1.0, 1.0]), np.array([8.0, 0.5, 0.5]), np.array([6.0, 0.0, 1.0])),
    (np.array([1.0, 1.0, 1.0]), np.array([8.0, 0.5, 0.5]), np.array([0.0, 5.0, 4.0])),
    (np.array([[2.0, 1.0], [2.0, 1.0]]), np.array([[0.1, 1.0], [3.9, 1.0]]), np.array([[0.0, 3.0], [7.0, 1.0]])),
]


@pytest.mark.parametrize("p, r, counts", CASES)
def test_matches_closed_form_evidence(p, r, counts):
    q = p + counts
    res = reduce_dirichlet(q, p, r)
    # F = F(alternative) - F(current) = -(ln p(o|r) - ln p(o|p))
    expected = dirichlet_multinomial_log_evidence(counts, p) - dirichlet_multinomial_log_evidence(counts, r)
    assert res.free_energy == pytest.approx(expected, abs=1e-10)
    np.testing.assert_allclose(res.posterior, r + counts)
    assert res.accept == (expected < 0)


def test_sign_convention_accepts_exactly_when_alternative_is_better():
    p = np.ones(2)
    r = np.array([10.0, 0.1])  # "expanded": believes outcome 0
    supporting = reduce_dirichlet(p + np.array([9.0, 0.0]), p, r)
    contradicting = reduce_dirichlet(p + np.array([0.0, 9.0]), p, r)
    assert supporting.free_energy < 0 and supporting.accept
    assert contradicting.free_energy > 0 and not contradicting.accept
    assert reduce_dirichlet(p + 3, p, p).free_energy == pytest.approx(0.0)  # same model: no change


def test_bad_input():
    with pytest.raises(SpecError, match="shapes differ"):
        reduce_dirichlet(np.ones(2), np.ones(3), np.ones(2))
    with pytest.raises(SpecError, match="negative counts"):
        reduce_dirichlet(np.array([1.0, 1.0]), np.array([5.0, 1.0]), np.array([1.0, 1.0]))


def test_exact_zero_in_reduced_prior_where_data_was_observed_rejects():
    p = np.array([1.0, 1.0, 1.0])
    q = p + np.array([3.0, 0.0, 1.0])  # outcome 2 was observed once
    r_zero = np.array([1.0, 1.0, 0.0])
    red = reduce_dirichlet(q, p, r_zero)
    assert red.free_energy == np.inf and not red.accept
    # the limit agrees: a tiny reduced prior there gives a large positive F
    tiny = reduce_dirichlet(q, p, np.array([1.0, 1.0, 1e-12]))
    assert tiny.free_energy > 20 and not tiny.accept
    # a zero where nothing was observed is a legitimate reduction (the entry is simply dropped)
    q2 = p + np.array([3.0, 1.0, 0.0])
    assert np.isfinite(reduce_dirichlet(q2, p, r_zero).free_energy)


def test_ties_keep_the_current_model_exactly():
    rng = np.random.default_rng(0)
    p = rng.random((4, 6)) * 3 + 0.1
    q = p + rng.random((4, 6)) * 5  # fractional counts (learning under uncertain beliefs)
    same = reduce_dirichlet(q, p, p.copy())
    assert same.free_energy == 0.0 and not same.accept
    # only the changed column counts; the unchanged ones add exactly nothing
    r = p.copy()
    r[:, 2] *= 2
    one = reduce_dirichlet(q, p, r).free_energy
    assert one == reduce_dirichlet(q[:, 2:3], p[:, 2:3], r[:, 2:3]).free_energy

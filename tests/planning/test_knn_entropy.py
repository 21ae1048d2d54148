import numpy as np
import pytest

from cogmap.planning.knn_entropy import debias_weights, knn_entropy, mutual_information

N = 5000


def _gauss_entropy(cov):
    return 0.5 * np.linalg.slogdet(2 * np.pi * np.e * np.atleast_2d(cov))[1]


def _gauss_error(d, seed):
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(d, d))
    cov = a @ a.T / d + 0.5 * np.eye(d)  # a random full covariance
    x = rng.multivariate_normal(np.zeros(d), cov, N)
    return knn_entropy(x) - _gauss_entropy(cov)


@pytest.mark.parametrize("d", [1, 2, 3, 4])
def test_gaussian_entropy(d):
    assert abs(_gauss_error(d, 0)) < 0.05


def test_gaussian_entropy_bias_over_seeds():
    # the sampling noise of any estimate at N = 5,000 is about sqrt(d / 2N) = 0.02 nats at d = 4;
    # over seeds the mean error (the bias) must stay well inside the 0.05 budget
    errs = [_gauss_error(4, s) for s in range(1, 6)]
    assert abs(np.mean(errs)) < 0.03


@pytest.mark.parametrize("d", [1, 2, 3, 4])
def test_uniform_entropy(d):
    rng = np.random.default_rng(200 + d)
    widths = np.linspace(0.5, 2.0, d)
    x = rng.uniform(0, widths, (N, d))
    truth = float(np.sum(np.log(widths)))
    assert abs(knn_entropy(x, support=(0.0, widths)) - truth) < 0.05
    assert abs(knn_entropy(x, support="data") - truth) < 0.05


def test_weights_and_plain_estimator():
    w = debias_weights(4, [1, 2, 4, 8])
    assert w.sum() == pytest.approx(1.0)
    x = np.random.default_rng(0).normal(size=(N, 1))
    assert abs(knn_entropy(x, ks=3) - _gauss_entropy(1.0)) < 0.05
    with pytest.raises(ValueError, match="k < N"):
        knn_entropy(x[:5], ks=8)
    with pytest.raises(ValueError, match="finite"):
        knn_entropy(np.array([[0.0], [np.nan], [1.0]]), ks=1)


def test_mutual_information_linear_gaussian():
    # x = m + n, m ~ N(0, s_m^2), n ~ N(0, s_n^2): I(x; m) = 0.5 log(1 + s_m^2 / s_n^2)
    rng = np.random.default_rng(3)
    s_m, s_n = 1.0, 0.5
    truth = 0.5 * np.log(1 + s_m**2 / s_n**2)
    marginal = rng.normal(0, s_m, 3000) + rng.normal(0, s_n, 3000)
    ms = rng.normal(0, s_m, 40)
    conditionals = ms[:, None] + rng.normal(0, s_n, (40, 500))
    assert mutual_information(marginal[:, None], conditionals) == pytest.approx(truth, abs=0.06)
    # independent x and m: no information
    indep = rng.normal(0, 1, (40, 500))
    assert abs(mutual_information(rng.normal(0, 1, (3000, 1)), indep)) < 0.05

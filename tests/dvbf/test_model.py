"""DVBF-LM model pieces: latent map, KL, charts, emission, transition."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

from cogmap.genmodel.charts import attention_weights, beam_query_points, bilinear_read, chart
from cogmap.genmodel.dvbf import (
    DVBFConfig,
    Emission,
    kinematic_mean,
    log_likelihood,
    predict_scan,
    transition_log_prob,
    transition_sample,
)
from cogmap.genmodel.latent_map import MapPosterior, init_map, kl_map, sample_map


def test_kl_matches_closed_form_and_monte_carlo():
    rng = np.random.default_rng(0)
    mean = rng.normal(size=(3, 4, 5))
    log_std = rng.normal(scale=0.3, size=(3, 4, 5))
    q = MapPosterior(jnp.asarray(mean), jnp.asarray(log_std))
    var = np.exp(2 * log_std)
    # KL(N(m, s^2) || N(0, 1)) = log(1/s) + (s^2 + m^2 - 1) / 2, per dimension
    expected = np.sum(-log_std + 0.5 * (var + mean**2 - 1))
    assert float(kl_map(q)) == pytest.approx(expected, rel=1e-5)
    assert float(kl_map(init_map(3, 4, 5))) == 0.0
    # Monte Carlo: E_q[log q - log p] from reparameterised samples
    keys = jax.random.split(jax.random.PRNGKey(1), 4000)
    samples = np.asarray(jax.jit(jax.vmap(lambda k: sample_map(k, q)))(keys))
    log_q = -0.5 * ((samples - mean) / np.exp(log_std)) ** 2 - log_std
    log_p = -0.5 * samples**2
    assert np.mean(np.sum(log_q - log_p, axis=(1, 2, 3))) == pytest.approx(expected, rel=0.05)


def test_bilinear_read_by_hand():
    # 4 x 3 grid over [0, 2]^2: cell side 0.5 along x, 2/3 along y; centres at 0.25 + 0.5 i, 1/3 + 2/3 j
    grid = jnp.arange(4 * 3 * 2, dtype=float).reshape(4, 3, 2)
    x, y = 0.6, 1.2
    u, v = x / 0.5 - 0.5, y / (2 / 3) - 0.5  # 0.7, 1.3
    i0, j0, fx, fy = 0, 1, 0.7, 0.3
    assert (u, v) == pytest.approx((i0 + fx, j0 + fy))
    g = np.asarray(grid)
    hand = ((1 - fx) * (1 - fy) * g[0, 1] + fx * (1 - fy) * g[1, 1] + (1 - fx) * fy * g[0, 2] + fx * fy * g[1, 2])
    got = bilinear_read(grid, jnp.array([x, y]), 2.0)
    assert np.allclose(got, hand)
    # the dense attention alpha(z) sums to 1 and gives the same read
    alpha = attention_weights(jnp.array([x, y]), (4, 3), 2.0)
    assert float(alpha.sum()) == pytest.approx(1.0)
    assert np.allclose(jnp.einsum("ij,ijd->d", alpha, grid), hand)
    # at a cell centre the read is that cell; beyond the border it is the border cell
    assert np.allclose(bilinear_read(grid, jnp.array([0.75, 1.0]), 2.0), g[1, 1])
    assert np.allclose(bilinear_read(grid, jnp.array([-1.0, -1.0]), 2.0), g[0, 0])


def test_query_points_rotate_and_translate():
    radii = jnp.array([0.0, 0.1, 0.2])
    pts = beam_query_points(jnp.array([0.5, 0.4, np.pi / 2]), 4, radii)
    assert pts.shape == (4, 3, 2)
    assert np.allclose(pts[0, 2], [0.5, 0.6], atol=1e-6)  # beam 0 along the heading (north)
    assert np.allclose(pts[1, 1], [0.4, 0.4], atol=1e-6)  # beam 1 a quarter turn on (west)
    # rotating the pose by one beam step rotates the chart's rows
    grid = jax.random.normal(jax.random.PRNGKey(0), (6, 6, 3))
    poses = jnp.array([[0.5, 0.5, 0.0], [0.5, 0.5, np.pi / 2]])
    rows = jax.jit(jax.vmap(lambda z: chart(grid, z, 1.0, 4, radii)))(poses)
    a, b = rows[0], rows[1]
    assert np.allclose(b[:3], a[1:], atol=1e-5) and np.allclose(b[3], a[0], atol=1e-5)


def test_emission_and_likelihood_shapes_and_gaussian():
    cfg = DVBFConfig(map_side=6, n_radii=4, hidden=8, depth=1)
    em = Emission(cfg, jax.random.PRNGKey(0))
    grid = jax.random.normal(jax.random.PRNGKey(1), (6, 6, cfg.map_dim))
    poses = jnp.array([[0.3, 0.3, 0.0], [0.6, 0.5, 1.0]])
    scan = jnp.full((cfg.n_beams,), 0.2)

    @eqx.filter_jit
    def compute(em):
        return jax.vmap(lambda z: predict_scan(em, grid, z, cfg))(poses), log_likelihood(em, grid, poses, scan, cfg)

    mu, ll = compute(em)
    assert mu.shape == (2, cfg.n_beams) and np.all((mu > 0) & (mu < cfg.lidar_range))
    s = cfg.sigma_e
    hand = [np.sum(-0.5 * ((0.2 - np.asarray(m)) / s) ** 2 - np.log(s) - 0.5 * np.log(2 * np.pi)) for m in mu]
    assert np.allclose(ll, hand, rtol=1e-5)


def test_engineered_transition_rotates_then_moves():
    z = jnp.array([[0.5, 0.5, 0.0]])
    u = jnp.array([np.pi / 2, 0.1])
    assert np.allclose(kinematic_mean(z, u), [[0.5, 0.6, np.pi / 2]], atol=1e-6)
    sig = jnp.array([0.01, 0.02, 0.05])
    s = transition_sample(jax.random.PRNGKey(0), jnp.tile(z, (20000, 1)), u, sig)
    assert np.allclose(np.std(np.asarray(s), 0), sig, rtol=0.05)
    lp = transition_log_prob(kinematic_mean(z, u), z, u, sig)
    assert float(lp[0]) == pytest.approx(-np.sum(np.log(np.asarray(sig))) - 1.5 * np.log(2 * np.pi), rel=1e-5)


def test_config_rejects_bad_sizes():
    with pytest.raises(ValueError, match="radii"):
        DVBFConfig(n_radii=3, radii=(0.0, 0.1))
    with pytest.raises(ValueError, match="sigma_e"):
        DVBFConfig(sigma_e=0.0)


def test_marginal_likelihood_variance_matches_monte_carlo():
    # with a small map std the delta-method variance of each predicted range matches sampling q(M)
    from cogmap.genmodel.dvbf import log_likelihood_marginal

    cfg = DVBFConfig(map_side=6, n_radii=4, hidden=8, depth=1, sigma_e=0.05)
    em = Emission(cfg, jax.random.PRNGKey(0))
    mean = jax.random.normal(jax.random.PRNGKey(1), (6, 6, cfg.map_dim))
    q = MapPosterior(mean, jnp.full(mean.shape, np.log(0.05)))
    z = jnp.array([0.4, 0.55, 0.3])
    radii = jnp.asarray(cfg.radii)

    @eqx.filter_jit
    def compute(em, q):
        m = chart(q.mean, z, cfg.extent, cfg.n_beams, radii)
        m_var = chart(jnp.exp(2 * q.log_std), z, cfg.extent, cfg.n_beams, radii, power=2)
        mu, var = em.mean_and_variance(m, m_var)
        keys = jax.random.split(jax.random.PRNGKey(2), 2000)
        samples = jax.vmap(lambda k: predict_scan(em, sample_map(k, q), z, cfg))(keys)
        return mu, var, samples, log_likelihood_marginal(em, q, z[None], mu + 0.01, cfg)[0]

    mu, var, samples, ll = compute(em, q)
    assert np.allclose(np.var(np.asarray(samples), 0), var, rtol=0.15, atol=1e-7)
    assert np.allclose(np.mean(np.asarray(samples), 0), mu, atol=2e-3)
    # the likelihood is a Gaussian per beam with the inflated variance
    total = cfg.sigma_e**2 + np.asarray(var)
    hand = np.sum(-0.5 * 0.01**2 / total - 0.5 * np.log(2 * np.pi * total))
    assert float(ll) == pytest.approx(hand, rel=1e-4)


@pytest.mark.parametrize("kwargs, message", [
    (dict(hidden=1e9), "DVBFConfig.hidden: expected an integer in 1..1024 (MAX_HIDDEN), got 1000000000.0"),
    (dict(hidden=10**9), "DVBFConfig.hidden: expected an integer in 1..1024 (MAX_HIDDEN), got 1000000000"),
    (dict(depth=0), "DVBFConfig.depth: expected an integer in 1..8 (MAX_DEPTH), got 0"),
    (dict(map_side=10**6), "DVBFConfig.map_side: expected an integer in 2..512 (MAX_MAP_SIDE)"),
    (dict(n_beams=True), "DVBFConfig.n_beams: expected an integer in 1..4096 (MAX_BEAMS), got True"),
    (dict(extent=float("nan")), "DVBFConfig.extent: expected a positive finite number, got nan"),
    (dict(sigma_t=(0.1, float("inf"), 0.1)), "DVBFConfig.sigma_t: expected three finite numbers >= 0"),
    (dict(hidden=1024, n_radii=1024, map_dim=256), "DVBFConfig: the emission network (input 262144, hidden 1024, "
                                                   "depth 2) has 269487105 parameters, above the limit of 20000000"),
])
def test_config_bounds_every_size_before_a_network_is_made(kwargs, message):
    with pytest.raises(ValueError) as err:
        DVBFConfig(**kwargs)
    assert str(err.value).startswith(message), str(err.value)


def _saved_model(tmp_path):
    from cogmap.inference.dvbf_files import save_params
    from cogmap.inference.elbo import init_params

    cfg = DVBFConfig(map_side=4, n_radii=3, hidden=8, depth=1)
    save_params(init_params(cfg, jax.random.PRNGKey(0)), cfg, tmp_path)
    with np.load(tmp_path / "model.npz") as z:
        arrays = {k: z[k] for k in z.files}
    return cfg, arrays


def test_a_saved_model_loads_back(tmp_path):
    from cogmap.inference.dvbf_files import load_params

    cfg, arrays = _saved_model(tmp_path)
    params, back = load_params(tmp_path)
    assert back == cfg
    assert np.array_equal(np.asarray(params.q_map.mean), arrays["q_map/mean"])


def test_an_emission_is_stored_once_and_whole(tmp_path):
    from cogmap.inference.dvbf_files import load_params, save_emission_once
    from cogmap.inference.elbo import init_params

    cfg = DVBFConfig(map_side=4, n_radii=3, hidden=8, depth=1)
    first = init_params(cfg, jax.random.PRNGKey(1)).emission
    second = init_params(cfg, jax.random.PRNGKey(2)).emission
    out = tmp_path / "cache" / "emission"
    save_emission_once(first, cfg, out)
    save_emission_once(second, cfg, out)  # another process came second: the first copy stays
    stored = load_params(out)[0].emission
    leaves = [np.asarray(x) for x in jax.tree_util.tree_leaves(eqx.filter(stored, eqx.is_array))]
    want = [np.asarray(x) for x in jax.tree_util.tree_leaves(eqx.filter(first, eqx.is_array))]
    assert all(np.array_equal(a, b) for a, b in zip(leaves, want, strict=True))
    assert sorted(p.name for p in out.parent.iterdir()) == ["emission"]  # no half-written folder left


@pytest.mark.parametrize("case", ["nan", "shape", "missing", "extra", "hidden", "unknown field"])
def test_a_damaged_model_file_is_refused_naming_the_array_or_field(tmp_path, case):
    import json

    from cogmap.inference.dvbf_files import DVBFModelError, load_params

    _, arrays = _saved_model(tmp_path)
    meta = json.loads((tmp_path / "model.json").read_text())
    if case == "nan":
        arrays = {k: np.full_like(v, np.nan) for k, v in arrays.items()}
        message = "has non-finite entries (NaN or infinite)"
    elif case == "shape":
        arrays["q_map/mean"] = arrays["q_map/mean"][:3]
        message = "array 'q_map/mean' has shape (3, 4, 20), expected (4, 4, 20) from the configuration in model.json"
    elif case == "missing":
        del arrays["q_map/log_std"]
        message = "missing array 'q_map/log_std'"
    elif case == "extra":
        arrays["junk"] = np.zeros(10**3)
        message = "unexpected array 'junk'"
    elif case == "hidden":
        meta["config"]["hidden"] = 1e9
        message = "model.json: config: DVBFConfig.hidden: expected an integer in 1..1024 (MAX_HIDDEN)"
    else:
        meta["config"]["batch"] = 8
        message = "model.json: config: unknown field(s) 'batch'"
    np.savez_compressed(tmp_path / "model.npz", **arrays)
    (tmp_path / "model.json").write_text(json.dumps(meta))
    with pytest.raises(DVBFModelError) as err:
        load_params(tmp_path)
    assert message in str(err.value) and "\n" not in str(err.value), str(err.value)

"""The pose search of pose-to-observation navigation: the grid, the table's likelihood against a direct
evaluation, and the refinement climbing the model's own likelihood to the pose an observation came from."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from cogmap.genmodel.dvbf import DVBFConfig, log_likelihood, predict_scan
from cogmap.inference.elbo import init_params
from cogmap.inference.pose_search import PoseTable, build_table, encode, pose_grid, refine, table_log_likelihood


def test_pose_grid_covers_cell_centres_and_headings():
    g = pose_grid(1.0, 4, 3)
    assert g.shape == (48, 3)
    assert np.allclose(np.unique(g[:, 0]), [0.125, 0.375, 0.625, 0.875])
    assert np.allclose(np.unique(g[:, 2]), [-np.pi, -np.pi / 3, np.pi / 3])
    with pytest.raises(ValueError, match="n_xy"):
        pose_grid(1.0, 0, 3)


def test_table_log_likelihood_is_the_gaussian_up_to_a_constant():
    rng = np.random.default_rng(0)
    table = PoseTable(rng.random((30, 3)), rng.random((30, 5)))
    obs = rng.random(5)
    ll = table_log_likelihood(obs, table, 0.1)
    direct = np.array([-0.5 * np.sum((obs - s) ** 2) / 0.01 for s in table.scans])
    np.testing.assert_allclose(ll, direct, rtol=1e-10, atol=1e-9)
    with pytest.raises(ValueError, match="beams"):
        table_log_likelihood(obs[:4], table, 0.1)


def _model():
    cfg = DVBFConfig(extent=1.0, map_side=8, hidden=16, lidar_range=0.53)
    params = init_params(cfg, jax.random.PRNGKey(2))
    # a random map: its predictions vary with the pose, so the likelihood has a mode
    grid = jax.random.normal(jax.random.PRNGKey(5), params.q_map.mean.shape)
    return cfg, params.emission, grid


def test_refine_climbs_the_model_likelihood_to_the_true_pose():
    cfg, emission, grid = _model()
    truth = jnp.array([0.43, 0.58, 0.7])
    obs = np.asarray(predict_scan(emission, grid, truth, cfg))
    start = np.array([[0.45, 0.56, 0.75]])
    z, ll = refine(emission, grid, cfg, obs, start, sigma=0.03, iters=300, lr=0.002)
    # the refined likelihood is the model's own (log_likelihood without its constant) and higher than at the start
    const = -cfg.n_beams * (np.log(0.03) + 0.5 * np.log(2 * np.pi))
    ref = np.asarray(log_likelihood(emission, grid, jnp.asarray(z, jnp.float32), jnp.asarray(obs), cfg, 0.03)) - const
    np.testing.assert_allclose(ll, ref, rtol=1e-4, atol=1e-3)
    ll0 = float(log_likelihood(emission, grid, jnp.asarray(start, jnp.float32), jnp.asarray(obs), cfg, 0.03)[0]) - const
    assert ll[0] > ll0
    assert np.hypot(*(z[0, :2] - np.asarray(truth[:2]))) < 0.01


def test_encode_finds_the_table_pose_an_observation_was_predicted_at():
    cfg, emission, grid = _model()

    def scan_fn(poses):
        return np.asarray(jax.vmap(lambda z: predict_scan(emission, grid, z, cfg))(jnp.asarray(poses, jnp.float32)))

    table = build_table(scan_fn, 1.0, n_xy=6, n_heading=4, chunk=50)
    assert table.poses.shape == (144, 3) and table.scans.shape == (144, cfg.n_beams)
    k = 77
    pose, ll = encode(table.scans[k], table, 0.03, top=3)
    assert np.allclose(pose, table.poses[k]) and abs(ll) < 1e-9  # its own prediction: log-likelihood 0

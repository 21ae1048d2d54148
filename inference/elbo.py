"""The DVBF-LM ELBO over mini-batches of time steps and its jitted SVI (Adam) step (paper Eq. 1-3).

The pose posterior is a particle filter without parameters of its own (paper III-C); its samples are
cached per time step (the asynchronous particle representation, III-D2). For a mini-batch ``B`` of
time steps with cached particles ``xi_t^(n)`` the loss is the map part of Eq. 3,

    L~ = T / |B| sum_{t in B} E_{M ~ q} [ sum_n w_tn (-log p(x_t | xi_t^(n), M)) ] + KL(q(M) || p(M)),

with ``w_tn`` the importance weights ``softmax_n log p(x_t | xi_t^(n), M)`` (importance resampling of
the cached particles under the current map sample, held fixed in the gradient). The pose KL term
``l^z`` does not depend on the map and emission parameters once the particles are cached, so it is
left out of the optimised loss. ``M`` is sampled with the reparameterisation trick (Bayes by backprop).
"""

from __future__ import annotations

from typing import NamedTuple

import equinox as eqx
import jax
import jax.numpy as jnp
import optax

from cogmap.genmodel.dvbf import DVBFConfig, Emission, log_likelihood
from cogmap.genmodel.latent_map import MapPosterior, init_map, kl_map, sample_map


class DVBFParams(NamedTuple):
    """Everything the ELBO optimises: ``q(M)`` and the emission network ``theta_E``."""

    q_map: MapPosterior
    emission: Emission


class Batch(NamedTuple):
    """``particles (B, P, 3)`` cached pose samples and ``scans (B, n_beams)`` of ``B`` time steps."""

    particles: jax.Array
    scans: jax.Array


class ELBOTerms(NamedTuple):
    loss: jax.Array
    reconstruction: jax.Array
    kl_map: jax.Array


def init_params(cfg: DVBFConfig, key: jax.Array) -> DVBFParams:
    return DVBFParams(init_map(cfg.map_side, cfg.map_side, cfg.map_dim), Emission(cfg, key))


def elbo_loss(params: DVBFParams, key: jax.Array, batch: Batch, n_total: int, cfg: DVBFConfig):
    """Negative ELBO estimate (Eq. 3) for one batch and one map sample; returns ``(loss, ELBOTerms)``."""
    grid = sample_map(key, params.q_map)
    ll = jax.vmap(lambda z, x: log_likelihood(params.emission, grid, z, x, cfg))(batch.particles, batch.scans)
    w = jax.nn.softmax(jax.lax.stop_gradient(ll), axis=1)
    recon = -(n_total / batch.scans.shape[0]) * jnp.sum(w * ll)
    kl = kl_map(params.q_map)
    loss = recon + kl
    return loss, ELBOTerms(loss, recon, kl)


def make_optimizer(learning_rate: float = 1e-3) -> optax.GradientTransformation:
    """Adam with the paper's beta_1 = 0.9 and epsilon = 1e-8 (Appendix B-H, D-A)."""
    return optax.adam(learning_rate, b1=0.9, eps=1e-8)


def init_opt_state(optimizer: optax.GradientTransformation, params: DVBFParams):
    return optimizer.init(eqx.filter(params, eqx.is_array))


def make_train_step(cfg: DVBFConfig, optimizer: optax.GradientTransformation, n_total: int):
    """A jitted ``step(params, opt_state, key, batch) -> (params, opt_state, ELBOTerms)``."""

    @eqx.filter_jit
    def step(params, opt_state, key, batch):
        (_, terms), grads = eqx.filter_value_and_grad(elbo_loss, has_aux=True)(params, key, batch, n_total, cfg)
        updates, opt_state = optimizer.update(grads, opt_state, eqx.filter(params, eqx.is_array))
        return eqx.apply_updates(params, updates), opt_state, terms

    return step

"""The latent map of DVBF-LM: a grid ``M`` of ``w x h`` cells, each a ``D_m``-vector (paper III-B).

Prior ``p(M_ij) = N(0, I)``; posterior ``q(M)`` mean-field Gaussian (III-C) with parameters
``mean`` and ``log_std`` of shape ``(w, h, D_m)``, index ``[i, j]`` with ``i`` along x and ``j``
along y. Samples are reparameterised (``mean + std * eps``), so gradients flow to both
parameters (Bayes by backprop). Pure JAX functions; jax is imported here only.
"""

from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp

MAP_DIM = 20


class MapPosterior(NamedTuple):
    """Variational parameters of ``q(M) = prod_ij N(mean_ij, diag(exp(log_std_ij))^2)``."""

    mean: jax.Array
    log_std: jax.Array


def init_map(width: int, height: int, dim: int = MAP_DIM) -> MapPosterior:
    """``q(M)`` equal to the prior N(0, I), as the paper initialises it (Appendix B-C)."""
    if width < 2 or height < 2 or dim < 1:
        raise ValueError(f"init_map: need width, height >= 2 and dim >= 1, got {(width, height, dim)}")
    shape = (int(width), int(height), int(dim))
    return MapPosterior(jnp.zeros(shape), jnp.zeros(shape))


def sample_map(key: jax.Array, q: MapPosterior) -> jax.Array:
    """One reparameterised sample ``M = mean + exp(log_std) * eps``, ``eps ~ N(0, I)``."""
    return q.mean + jnp.exp(q.log_std) * jax.random.normal(key, q.mean.shape)


def kl_map(q: MapPosterior) -> jax.Array:
    """Closed-form ``KL(q(M) || N(0, I))`` summed over every cell and dimension, in nats."""
    var = jnp.exp(2.0 * q.log_std)
    return 0.5 * jnp.sum(var + q.mean**2 - 1.0 - 2.0 * q.log_std)

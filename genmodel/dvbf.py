"""The DVBF-LM generative model for LiDAR mazes (paper Section III, Appendix B).

    p(x, z, m, M | u) = p(M) p(z_1) prod_t p(x_t | m_t) p(m_t | z_t, M) prod_t p(z_{t+1} | z_t, u_t)

* ``M``: latent map, :mod:`cogmap.genmodel.latent_map`;
* ``m_t``: chart read bilinearly at query points along the beams, :mod:`cogmap.genmodel.charts`;
* ``p(x_t | m_t) = N(mu_E(m_t), sigma_E^2 I)``: :class:`Emission`, an MLP shared over beams that maps
  the chart row of one beam to that beam's mean range (squashed into ``(0, lidar_range)``);
* ``p(z_{t+1} | z_t, u_t)``: the engineered transition :func:`kinematic_mean` (rotate, then move
  along the heading; Appendix A-A) with Gaussian noise ``sigma_T`` (Appendix D-A: known transition).

Neural networks use equinox: a model is a pytree of plain arrays with no hidden state, so the
emission network passes through ``jax.jit``, ``jax.grad`` and optax like any other array argument,
in keeping with the toolkit's pure-function style. equinox and jax are imported only here and in
the other DVBF modules, never by the core toolkit.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from .charts import chart
from .latent_map import MAP_DIM
from .numerics import wrap_angle

LOG_2PI = float(np.log(2 * np.pi))
#: bounds on the sizes of a DVBF-LM model (checked by :class:`DVBFConfig` before any array is
#: made, so a model file cannot ask for more): map cells per side (Table II uses at most 75),
#: dimension of a map cell (the paper's 20), LiDAR beams (20), query points per beam (12), width
#: and depth of the emission network (64 and 2)
MAX_MAP_SIDE = 512
MAX_MAP_DIM = 256
MAX_BEAMS = 4096
MAX_RADII = 1024
MAX_HIDDEN = 1024
MAX_DEPTH = 8
#: largest number of weights of the emission network (the defaults have about 20,000)
MAX_EMISSION_PARAMS = 20_000_000
#: largest side of the square world the map covers (the mazes are unit squares)
MAX_EXTENT = 1000.0


def _finite(v) -> bool:
    return not isinstance(v, bool | np.bool_) and isinstance(v, int | float | np.integer | np.floating) \
        and bool(np.isfinite(v))


@dataclass(frozen=True)
class DVBFConfig:
    """Static sizes and noise levels of one DVBF-LM model (defaults: paper Appendix B and D).

    ``extent``: side of the square world the map covers; ``map_side``: cells per side (Table II);
    ``radii``: distances of the chart's query points along each beam; ``sigma_e``: emission std
    used for learning (0.1 in the paper); ``sigma_t``: transition std of ``(x, y, phi)`` per step.
    """

    extent: float = 1.0
    map_side: int = 25
    map_dim: int = MAP_DIM
    n_beams: int = 20
    lidar_range: float = 0.53
    n_radii: int = 12
    sigma_e: float = 0.1
    sigma_t: tuple[float, float, float] = (0.002, 0.002, 0.01)
    hidden: int = 64
    depth: int = 2
    radii: tuple[float, ...] = field(default=(), compare=False)

    def __post_init__(self):
        for name, hi, limit in (("map_side", MAX_MAP_SIDE, "MAX_MAP_SIDE"), ("map_dim", MAX_MAP_DIM, "MAX_MAP_DIM"),
                                ("n_beams", MAX_BEAMS, "MAX_BEAMS"), ("n_radii", MAX_RADII, "MAX_RADII"),
                                ("hidden", MAX_HIDDEN, "MAX_HIDDEN"), ("depth", MAX_DEPTH, "MAX_DEPTH")):
            v, lo = getattr(self, name), 2 if name == "map_side" else 1
            if isinstance(v, bool | np.bool_) or not isinstance(v, int | np.integer) or not lo <= v <= hi:
                raise ValueError(f"DVBFConfig.{name}: expected an integer in {lo}..{hi} ({limit}), got {v!r}")
        for name in ("extent", "lidar_range", "sigma_e"):
            v = getattr(self, name)
            if not _finite(v) or v <= 0:
                raise ValueError(f"DVBFConfig.{name}: expected a positive finite number, got {v!r}")
        if self.extent > MAX_EXTENT:
            raise ValueError(f"DVBFConfig.extent: {self.extent!r} above the limit of {MAX_EXTENT:g} (MAX_EXTENT)")
        if not (isinstance(self.sigma_t, tuple | list) and len(self.sigma_t) == 3
                and all(_finite(v) and v >= 0 for v in self.sigma_t)):
            raise ValueError(f"DVBFConfig.sigma_t: expected three finite numbers >= 0 (x, y, phi), "
                             f"got {self.sigma_t!r}")
        if not isinstance(self.radii, tuple | list) or not all(_finite(v) for v in self.radii):
            raise ValueError(f"DVBFConfig.radii: expected finite numbers, got {self.radii!r}")
        n_in = self.n_radii * self.map_dim
        params = (n_in + 1) * self.hidden + (self.depth - 1) * (self.hidden + 1) * self.hidden + self.hidden + 1
        if params > MAX_EMISSION_PARAMS:
            raise ValueError(f"DVBFConfig: the emission network (input {n_in}, hidden {self.hidden}, depth "
                             f"{self.depth}) has {params} parameters, above the limit of {MAX_EMISSION_PARAMS} "
                             f"(MAX_EMISSION_PARAMS)")
        if not self.radii:
            object.__setattr__(self, "radii", tuple(np.linspace(0.0, self.lidar_range, self.n_radii).tolist()))
        elif len(self.radii) != self.n_radii:
            raise ValueError(f"DVBFConfig: {len(self.radii)} radii given, n_radii = {self.n_radii}")


def softsign(x: jax.Array) -> jax.Array:
    """``x / (1 + |x|)``, the emission network's activation (paper Table I)."""
    return x / (1.0 + jnp.abs(x))


class Emission(eqx.Module):
    """``mu_E``: chart ``(n_beams, n_radii, D)`` to mean ranges ``(n_beams,)``, one MLP shared by beams."""

    mlp: eqx.nn.MLP
    lidar_range: float = eqx.field(static=True)

    def __init__(self, cfg: DVBFConfig, key: jax.Array):
        self.mlp = eqx.nn.MLP(cfg.n_radii * cfg.map_dim, 1, cfg.hidden, cfg.depth,
                              activation=softsign, key=key)
        self.lidar_range = float(cfg.lidar_range)

    def beam(self, row: jax.Array) -> jax.Array:
        """Mean range of one beam from its chart row ``(n_radii, D)``."""
        return self.lidar_range * jax.nn.sigmoid(self.mlp(row.reshape(-1))[0])

    def __call__(self, m: jax.Array) -> jax.Array:
        return jax.vmap(self.beam)(m)

    def mean_and_variance(self, m: jax.Array, m_var: jax.Array) -> tuple[jax.Array, jax.Array]:
        """Mean ranges and their first-order (delta-method) variance under chart variances ``m_var``:
        ``Var mu_k ~ sum_j (d mu_k / d m_kj)^2 Var m_kj``."""
        mu, grad = jax.vmap(jax.value_and_grad(self.beam))(m)
        return mu, jnp.sum(grad**2 * m_var, axis=(1, 2))


def predict_scan(emission: Emission, grid: jax.Array, pose: jax.Array, cfg: DVBFConfig) -> jax.Array:
    """Mean LiDAR scan ``(n_beams,)`` at ``pose`` given a map sample ``grid``."""
    return emission(chart(grid, pose, cfg.extent, cfg.n_beams, jnp.asarray(cfg.radii)))


def log_likelihood(emission: Emission, grid: jax.Array, poses: jax.Array, scan: jax.Array,
                   cfg: DVBFConfig, sigma: float | None = None) -> jax.Array:
    """``log p(x | z_k, M)`` for poses ``(K, 3)``; Gaussian per beam with std ``sigma`` (default sigma_e)."""
    s = cfg.sigma_e if sigma is None else sigma
    mu = jax.vmap(lambda z: predict_scan(emission, grid, z, cfg))(poses)
    r = (scan - mu) / s
    return -0.5 * jnp.sum(r * r, -1) - scan.shape[-1] * (jnp.log(s) + 0.5 * LOG_2PI)


def log_likelihood_marginal(emission: Emission, q_map, poses: jax.Array, scan: jax.Array, cfg: DVBFConfig,
                            sigma: float | None = None) -> jax.Array:
    """``log E_q(M) p(x | z_k, M)`` to first order: per beam a Gaussian around the prediction at the map
    mean whose variance adds the map's uncertainty carried through the emission (delta method).
    Beams that look into unlearnt parts of the map (std near the prior's 1) then weigh little."""
    s = cfg.sigma_e if sigma is None else sigma
    radii = jnp.asarray(cfg.radii)
    var_grid = jnp.exp(2.0 * q_map.log_std)

    def one(z):
        m = chart(q_map.mean, z, cfg.extent, cfg.n_beams, radii)
        m_var = chart(var_grid, z, cfg.extent, cfg.n_beams, radii, power=2)
        return emission.mean_and_variance(m, m_var)

    mu, var = jax.vmap(one)(poses)
    total = s * s + var
    r2 = (scan - mu) ** 2 / total
    return -0.5 * jnp.sum(r2 + jnp.log(total), -1) - 0.5 * scan.shape[-1] * LOG_2PI


def kinematic_mean(z: jax.Array, u: jax.Array) -> jax.Array:
    """Engineered transition mean for poses ``(..., 3)`` and controls ``(..., 2) = (d_phi, d_p)``:
    rotate first, then move ``d_p`` along the new heading (Appendix A-A)."""
    phi = z[..., 2] + u[..., 0]
    return jnp.stack([z[..., 0] + u[..., 1] * jnp.cos(phi), z[..., 1] + u[..., 1] * jnp.sin(phi), wrap_angle(phi)], -1)


def transition_sample(key: jax.Array, z: jax.Array, u: jax.Array, sigma_t) -> jax.Array:
    """Sample ``z' ~ N(kinematic_mean(z, u), diag(sigma_t^2))`` for poses ``(K, 3)``."""
    noise = jnp.asarray(sigma_t) * jax.random.normal(key, z.shape)
    out = kinematic_mean(z, u) + noise
    return out.at[..., 2].set(wrap_angle(out[..., 2]))


def transition_log_prob(z_next: jax.Array, z: jax.Array, u: jax.Array, sigma_t) -> jax.Array:
    """``log p(z' | z, u)`` of the engineered transition (heading residual wrapped)."""
    s = jnp.asarray(sigma_t)
    d = z_next - kinematic_mean(z, u)
    d = d.at[..., 2].set(wrap_angle(d[..., 2]))
    return -0.5 * jnp.sum((d / s) ** 2, -1) - jnp.sum(jnp.log(s)) - 1.5 * LOG_2PI


def maze_config(extent: float, map_side: int, rot_std: float, hidden: int = 64, sigma_xy: float = 0.0005) -> DVBFConfig:
    """The DVBF-LM configuration the runs and studies use for a maze: its extent and map side,
    ``hidden`` units, and a transition noise of ``sigma_xy`` in x and y and the actuation's heading std.

    Parameters
    ----------
    extent : float
        Side of the world (the maze's ``size``).
    map_side : int
        Map cells per side (the maze's ``map_side``, Table II).
    rot_std : float
        Heading std per step of the robot's actuation, radians.
    hidden : int, optional
        Hidden units of the emission network, default 64.
    sigma_xy : float, optional
        Transition std of x and y per step, default 0.0005.

    Returns
    -------
    DVBFConfig
    """
    return DVBFConfig(extent=extent, map_side=map_side, hidden=hidden, sigma_t=(sigma_xy, sigma_xy, rot_std))

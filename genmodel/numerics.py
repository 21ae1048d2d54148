"""The small numerics every library layer shares: one log floor, softmax, normalisation.

``genmodel`` is the lowest layer, so ``inference`` and ``planning`` import these from here
(the old names, ``inference.base.LOG_FLOOR``/``floor_log``/``softmax``, ``planning.efe.EPS``/
``xlogx``, ``planning.policies.softmax`` and ``genmodel.normalise``, stay importable).
"""

from __future__ import annotations

import numpy as np

#: floor of a probability before its log (machine epsilon): ``0 log 0 = 0`` and a zero
#: likelihood costs ``-ln eps ~ 36`` nats, not infinity
LOG_FLOOR = float(np.finfo(float).eps)
#: floor that only keeps a log finite (KL divergences, exact log-likelihoods)
TINY_FLOOR = 1e-300


def floor_log(x, floor: float = LOG_FLOOR) -> np.ndarray:
    """``ln max(x, floor)``."""
    return np.log(np.maximum(x, floor))


def xlogx(x: np.ndarray) -> np.ndarray:
    """``x ln x`` elementwise with ``0 ln 0 = 0`` (log floored at :data:`LOG_FLOOR`)."""
    return x * np.log(np.maximum(x, LOG_FLOOR))


def xlogx_sum(q: np.ndarray) -> float:
    """``sum q ln q`` over the positive entries (exact, no floor): minus the entropy."""
    nz = q > 0
    return float(np.sum(q[nz] * np.log(q[nz])))


def softmax(x: np.ndarray) -> np.ndarray:
    """``exp(x) / sum exp(x)`` over all entries, shifted by the maximum for stability."""
    e = np.exp(x - x.max())
    return e / e.sum()


def normalise(x: np.ndarray, axis: int = 0) -> np.ndarray:
    """Normalise along ``axis``; all-zero columns become uniform.

    Parameters
    ----------
    x : array_like
        Non-negative values.
    axis : int, optional
        Axis that sums to 1 afterwards, default 0.

    Returns
    -------
    numpy.ndarray
        Float array of the shape of ``x``.
    """
    x = np.asarray(x, dtype=float)
    s = x.sum(axis=axis, keepdims=True)
    n = x.shape[axis]
    return np.where(s > 0, x / np.where(s > 0, s, 1.0), 1.0 / n)


def wrap_angle(a):
    """Angles wrapped to ``[-pi, pi)``: ``(a + pi) mod 2 pi - pi``, elementwise.

    The one angle wrap of the toolkit: numpy arrays, scalars and sequences (as float arrays) and
    jax arrays (traced too, returned as jax arrays) alike.

    Parameters
    ----------
    a : float, array_like or jax.Array
        Angles in radians.

    Returns
    -------
    numpy.ndarray or jax.Array
        The wrapped angles, same shape (a 0-d array for a number).
    """
    if type(a).__module__.split(".")[0] not in ("jax", "jaxlib"):
        a = np.asarray(a, dtype=float)
    return (a + np.pi) % (2 * np.pi) - np.pi


def floor_log_jax(x):
    """:func:`floor_log` for JAX arrays (traced too): ``ln max(x, eps)``."""
    import jax.numpy as jnp

    return jnp.log(jnp.maximum(x, LOG_FLOOR))


def xlogx_jax(x):
    """:func:`xlogx` for JAX arrays (traced too): ``x ln max(x, eps)``."""
    return x * floor_log_jax(x)

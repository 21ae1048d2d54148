"""State inference schemes behind one call, a registry, and a bridge to pymdp 1.0.

Every scheme: ``posterior, info = scheme(model, prior, observations, actions=None, **options)``
(conventions in :mod:`cogmap.inference.base`). Built-in names: ``exact``, ``filter``
(:func:`bayes_filter`), ``fpi``, ``vmp``, ``mmp``, ``kernel``
(:func:`kernel_filter`, the drone's Gaussian-kernel update over binned factors), ``particle_filter``
(continuous states, jax imported on call); ``get(name)``, ``register(name, fn)``, ``available()``.
"""

from .base import (
    POSE_KEY,
    Evidence,
    InferenceError,
    InferenceInfo,
    Problem,
    predict_factorised,
    prepare,
)
from .bayes_filter import bayes_filter
from .exact import exact
from .fpi import fpi
from .free_energy import window_free_energy
from .kernel_filter import kernel_filter
from .message_passing import mmp, vmp
from .particle_scheme import ParticleModel, particle_filter
from .pymdp_bridge import to_pymdp
from .registry import available, get, register, unregister

_BUILTIN = (("exact", exact), ("filter", bayes_filter), ("fpi", fpi), ("vmp", vmp), ("mmp", mmp),
            ("kernel", kernel_filter), ("particle_filter", particle_filter))
for _name, _fn in _BUILTIN:
    register(_name, _fn)

__all__ = [
    "POSE_KEY",
    "Evidence",
    "InferenceError",
    "InferenceInfo",
    "ParticleModel",
    "Problem",
    "available",
    "bayes_filter",
    "exact",
    "fpi",
    "get",
    "kernel_filter",
    "mmp",
    "particle_filter",
    "predict_factorised",
    "prepare",
    "register",
    "to_pymdp",
    "unregister",
    "vmp",
    "window_free_energy",
]

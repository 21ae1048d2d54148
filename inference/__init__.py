"""State inference schemes behind one call, a registry, and a bridge to pymdp 1.0.

Every scheme: ``posterior, info = scheme(model, prior, observations, actions=None, **options)``
(conventions in :mod:`cogmap.inference.base`). Built-in names: ``exact``, ``filter``
(:func:`bayes_filter`), ``fpi``, ``vmp`` (coordinate ascent on the mean-field free energy,
:mod:`~cogmap.inference.mean_field`), ``vmp_pymdp`` and ``mmp`` (pymdp 1.0's simultaneous updates,
:mod:`~cogmap.inference.message_passing`), ``kernel`` (:func:`kernel_filter`, the drone's
Gaussian-kernel update over binned factors), ``particle_filter`` (continuous states, jax imported
on call); ``get(name)``, ``register(name, fn, accepts=...)``,
``available()``, ``accepting(model)`` (the schemes that handle a model).
"""

from cogmap.genmodel.drone_beliefs import KernelBeliefModel
from cogmap.genmodel.model import Model

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
from .mean_field import vmp
from .message_passing import mmp, vmp_pymdp
from .particle_scheme import ParticleModel, particle_filter
from .pymdp_bridge import to_pymdp
from .registry import accepting, accepts, available, get, register, unregister


def _one_factor(model) -> bool:
    return isinstance(model, Model) and len(model.factors) == 1


_BUILTIN = (("exact", exact, Model), ("filter", bayes_filter, _one_factor), ("fpi", fpi, Model),
            ("vmp", vmp, Model), ("vmp_pymdp", vmp_pymdp, Model), ("mmp", mmp, Model),
            ("kernel", kernel_filter, KernelBeliefModel), ("particle_filter", particle_filter, ParticleModel))
for _name, _fn, _accepts in _BUILTIN:
    register(_name, _fn, accepts=_accepts)

__all__ = [
    "POSE_KEY",
    "Evidence",
    "InferenceError",
    "InferenceInfo",
    "ParticleModel",
    "accepting",
    "accepts",
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
    "vmp_pymdp",
    "window_free_energy",
]

"""State inference schemes behind one call, a registry, and a bridge to pymdp 1.0.

Every scheme: ``posterior, info = scheme(model, prior, observations, actions=None, **options)``
(conventions in :mod:`cogmap.inference.base`). Built-in names: ``exact``, ``filter``, ``fpi``,
``vmp``, ``mmp``; ``get(name)``, ``register(name, fn)``, ``available()``.
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
from .exact import exact
from .filter import filter  # noqa: A004 - scheme name
from .fpi import fpi
from .message_passing import mmp, vmp
from .pymdp_bridge import to_pymdp
from .registry import available, get, register, unregister

for _name, _fn in (("exact", exact), ("filter", filter), ("fpi", fpi), ("vmp", vmp), ("mmp", mmp)):
    register(_name, _fn)

__all__ = [
    "POSE_KEY",
    "Evidence",
    "InferenceError",
    "InferenceInfo",
    "Problem",
    "available",
    "exact",
    "filter",
    "fpi",
    "get",
    "mmp",
    "predict_factorised",
    "prepare",
    "register",
    "to_pymdp",
    "unregister",
    "vmp",
]

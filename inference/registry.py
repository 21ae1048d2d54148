"""Registry of inference schemes by name.

A scheme is any callable ``scheme(model, prior, observations, actions=None, **options)``
returning ``(posterior, info)`` (see :mod:`cogmap.inference.base`). Users add their own with
:func:`register` without touching this package; the registry checks each one against the
contract (:class:`cogmap.genmodel.contracts.InferenceScheme`) when it is registered.
"""

from __future__ import annotations

import inspect

from cogmap.genmodel.contracts import InferenceScheme
from cogmap.genmodel.registry import Registry

#: the arguments every scheme takes; anything else it accepts is one of its options
CALL = ("model", "prior", "observations", "actions")

#: the registered schemes; ``register(name, fn, *, accepts=None, overwrite=False)`` (a
#: decorator without ``fn``), ``unregister``, ``get``, ``available``, ``accepts(name, model)`` and
#: ``accepting(model)`` are its methods. ``accepts`` names the models a scheme handles (a model
#: type, a tuple of them or a test ``accepts(model) -> bool``): :func:`accepting` and
#: ``compare-inference`` offer the scheme only for such models.
SCHEMES = Registry("inference scheme", "register", protocol=InferenceScheme, expected="a callable")
register = SCHEMES.register
unregister = SCHEMES.remove
get = SCHEMES.get
available = SCHEMES.available
accepts = SCHEMES.accepts
accepting = SCHEMES.accepting


def options(name: str) -> tuple[str, ...] | None:
    """The keyword options the scheme registered under ``name`` accepts, from its signature.

    A scheme declares its options as the parameters after ``(model, prior, observations,
    actions)``, e.g. ``fpi(..., *, num_iter=16, tol=None)``.

    Parameters
    ----------
    name : str
        Registered name.

    Returns
    -------
    tuple of str or None
        The option names, in order; None when the scheme takes any keyword (``**options``) or its
        signature cannot be read.

    Raises
    ------
    KeyError
        If no scheme has that name.
    """
    fn = get(name)
    try:
        params = list(inspect.signature(fn).parameters.values())
    except (TypeError, ValueError):
        return None
    if any(p.kind is inspect.Parameter.VAR_KEYWORD for p in params):
        return None
    return tuple(p.name for p in params if p.name not in CALL
                 and p.kind in (inspect.Parameter.KEYWORD_ONLY, inspect.Parameter.POSITIONAL_OR_KEYWORD))


def check_options(name: str, given) -> None:
    """Refuse options the scheme ``name`` does not accept (see :func:`options`), before it runs.

    Parameters
    ----------
    name : str
        Registered name.
    given : iterable of str
        The option names to be passed.

    Raises
    ------
    KeyError
        If no scheme has that name.
    InferenceError
        Naming the option, the scheme and the options it accepts.
    """
    from .base import InferenceError

    known = options(name)
    for key in given:
        if key in CALL:
            raise InferenceError(f"'{key}' is an argument of every inference scheme, not an option of '{name}'")
        if known is not None and key not in known:
            accepted = f"its options: {', '.join(known)}" if known else "it takes no options"
            raise InferenceError(f"inference scheme '{name}' has no option '{key}' ({accepted})")

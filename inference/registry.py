"""Registry of inference schemes by name.

A scheme is any callable ``scheme(model, prior, observations, actions=None, **options)``
returning ``(posterior, info)`` (see :mod:`cogmap.inference.base`). Users add their own with
:func:`register` without touching this package.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable

from cogmap.genmodel.contracts import InferenceScheme, check_conforms
from cogmap.genmodel.registry import accepts_test, passes

#: the arguments every scheme takes; anything else it accepts is one of its options
CALL = ("model", "prior", "observations", "actions")

_SCHEMES: dict[str, Callable] = {}
_ACCEPTS: dict[str, Callable[[object], bool]] = {}


def register(name: str, fn: Callable | None = None, *, accepts=None, overwrite: bool = False):
    """Register an inference scheme under ``name``; usable as a decorator (``@register("mine")``).

    A scheme is any callable ``scheme(model, prior, observations, actions=None, **options)``
    returning ``(posterior, info)`` (:class:`cogmap.genmodel.contracts.InferenceScheme`).

    Parameters
    ----------
    name : str
        Non-empty name.
    fn : callable, optional
        The scheme; omit to get a decorator.
    accepts : type, tuple of types or callable, optional
        The models the scheme handles: a model type (or tuple of them), or a test
        ``accepts(model) -> bool``. :func:`accepting` and ``compare-inference`` offer the scheme
        only for such models. Default: every model.
    overwrite : bool, optional
        Whether to replace another scheme of the same name, default False.

    Returns
    -------
    callable
        ``fn`` itself, or a decorator that registers and returns its argument.

    Raises
    ------
    ValueError
        For an empty name, or a name taken by another scheme without ``overwrite``.
    TypeError
        If the scheme is not callable, cannot be called as ``scheme(model, prior, observations)``,
        or ``accepts`` is neither a type nor a callable.
    """
    if not isinstance(name, str) or not name:
        raise ValueError("register: name must be a non-empty string")
    test = accepts_test(f"register('{name}')", accepts)

    def _add(f: Callable) -> Callable:
        if not callable(f):
            raise TypeError(f"register('{name}'): expected a callable, got {type(f).__name__}")
        check_conforms("register", "inference scheme", name, f, InferenceScheme)
        if name in _SCHEMES and not overwrite and _SCHEMES[name] is not f:
            raise ValueError(f"register: a scheme named '{name}' exists (pass overwrite=True)")
        _SCHEMES[name] = f
        _ACCEPTS[name] = test
        return f

    return _add if fn is None else _add(fn)


def unregister(name: str) -> None:
    """Remove the scheme registered under ``name``.

    Parameters
    ----------
    name : str
        Registered name.

    Raises
    ------
    KeyError
        If no scheme has that name.
    """
    if name not in _SCHEMES:
        raise KeyError(f"no inference scheme named '{name}'")
    del _SCHEMES[name]
    _ACCEPTS.pop(name, None)


def get(name: str) -> Callable:
    """The scheme registered under ``name``.

    Parameters
    ----------
    name : str
        Registered name (``available()`` lists them).

    Returns
    -------
    callable
        ``scheme(model, prior, observations, actions=None, **options) -> (posterior, info)``.

    Raises
    ------
    KeyError
        If no scheme has that name (the message lists the available ones).
    """
    try:
        return _SCHEMES[name]
    except KeyError:
        raise KeyError(f"unknown inference scheme '{name}' (available: {available()})") from None


def available() -> tuple[str, ...]:
    """Names of the registered schemes.

    Returns
    -------
    tuple of str
        Sorted names.
    """
    return tuple(sorted(_SCHEMES))


def accepts(name: str, model) -> bool:
    """Whether the scheme registered under ``name`` handles ``model`` (its ``accepts``).

    Parameters
    ----------
    name : str
        Registered name.
    model : object
        A model (``Model``, ``ParticleModel``, ``KernelBeliefModel``, ...).

    Returns
    -------
    bool

    Raises
    ------
    KeyError
        If no scheme has that name.
    """
    get(name)
    return _test(name, model)


def accepting(model) -> tuple[str, ...]:
    """Names of the registered schemes that handle ``model`` (sorted).

    Parameters
    ----------
    model : object
        A model.

    Returns
    -------
    tuple of str
    """
    return tuple(n for n in available() if _test(n, model))


def _test(name: str, model) -> bool:
    return passes(_ACCEPTS[name], model)


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

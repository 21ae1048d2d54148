"""The checks every registry of the toolkit makes when something is registered (EFE terms,
planners, rooms, observation encoders), so that all of them refuse the same mistakes with the
same messages."""

from __future__ import annotations

from collections.abc import Container, Mapping

from .contracts import check_conforms


def check_name(func: str, name) -> None:
    """Refuse a name that is not a non-empty string.

    Parameters
    ----------
    func : str
        The registering function's name, for the message (e.g. ``"register_planner"``).
    name : object
        The name asked for.

    Raises
    ------
    ValueError
        ``name`` is not a non-empty string.
    """
    if not isinstance(name, str) or not name:
        raise ValueError(f"{func}: name must be a non-empty string, got {name!r}")


def check_entry(func: str, kind: str, name: str, obj, table: Mapping, builtin: Container, overwrite: bool,
                expected: str = "a callable", same_again: bool = True, protocol=None) -> None:
    """Refuse registering ``obj`` under ``name``: not callable, not conforming to its contract, a
    built-in name, or a taken name without ``overwrite`` (registering the same object again is
    allowed unless ``same_again`` is false).

    Parameters
    ----------
    func : str
        The registering function's name, for the message.
    kind : str
        What is registered (``"planner"``, ``"EFE term"``, ...), for the message.
    name : str
        The name asked for (already checked by :func:`check_name`).
    obj : object
        What is registered.
    table : Mapping
        The registry's entries so far, name -> object.
    builtin : Container
        The built-in names, which cannot be replaced.
    overwrite : bool
        Whether a name registered earlier may be replaced.
    expected : str, optional
        What ``obj`` should be, for the message (e.g. ``"a callable factory(seed) -> Layout"``).
    same_again : bool, optional
        Whether registering the very same object again under its name is accepted (default True;
        a registry whose registration has side effects, such as a Gymnasium id, passes False).
    protocol : type, optional
        The contract of :mod:`cogmap.genmodel.contracts` ``obj`` must meet
        (:func:`~cogmap.genmodel.contracts.check_conforms`).

    Raises
    ------
    TypeError
        ``obj`` is not callable, or does not meet ``protocol``.
    ValueError
        ``name`` is built in, or taken and ``overwrite`` is false.
    """
    if not callable(obj):
        raise TypeError(f"{func}('{name}'): expected {expected}, got {type(obj).__name__}")
    if protocol is not None:
        check_conforms(func, kind, name, obj, protocol)
    again = same_again and table.get(name) is obj
    if name in builtin and not again:
        raise ValueError(f"{func}: '{name}' is a built-in {kind}; choose another name")
    if name in table and not overwrite and not again:
        raise ValueError(f"{func}: a {kind} named '{name}' exists (pass overwrite=True)")

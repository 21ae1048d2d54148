"""The checks every registry of the toolkit makes when something is registered (EFE terms,
planners, rooms, observation encoders), so that all of them refuse the same mistakes with the
same messages."""

from __future__ import annotations

from collections.abc import Callable, Container, Mapping

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


def accepts_test(func: str, accepts) -> Callable[[object], bool]:
    """The model test of an entry registered with ``accepts`` (a type, a tuple of types, a callable
    ``accepts(model) -> bool``, or None for every model).

    Parameters
    ----------
    func : str
        The registering function, for the message.
    accepts : type, tuple of types, callable or None
        What the entry handles.

    Returns
    -------
    callable
        ``test(model) -> bool``.

    Raises
    ------
    TypeError
        ``accepts`` is none of these.
    """
    if accepts is None:
        return lambda model: True
    if isinstance(accepts, type) or (isinstance(accepts, tuple) and accepts
                                     and all(isinstance(t, type) for t in accepts)):
        return lambda model: isinstance(model, accepts)
    if callable(accepts):
        return accepts
    raise TypeError(f"{func}: accepts must be a model type, a tuple of types or a callable "
                    f"accepts(model) -> bool, got {type(accepts).__name__}")


def passes(test: Callable[[object], bool], model) -> bool:
    """``test(model)``, where a test that fails on a model of another kind (say, reading
    ``model.factors`` of a particle model) counts as not accepting it.

    Parameters
    ----------
    test : callable
        From :func:`accepts_test`.
    model : object
        Any model.

    Returns
    -------
    bool
    """
    try:
        return bool(test(model))
    except Exception:  # noqa: BLE001 - a user's test may assume its own model type
        return False


class Registry:
    """Named entries of one kind, each checked against its contract when added; the names present
    when :meth:`seal` is called are built in (they can be neither replaced nor removed).

    Parameters
    ----------
    kind : str
        What is registered (``"agent"``, ``"study"``), for the messages.
    func : str
        The registering function's name, for the messages (``"register_agent"``).
    protocol : type, optional
        The contract of :mod:`cogmap.genmodel.contracts` every entry must meet.
    missing : type, optional
        The exception :meth:`get` raises for an unknown name, default ``KeyError``.
    """

    def __init__(self, kind: str, func: str, protocol=None, missing: type[Exception] = KeyError):
        self.kind, self.func, self.protocol, self.missing = kind, func, protocol, missing
        self._entries: dict = {}
        self._builtin: frozenset[str] = frozenset()

    def add(self, name: str, entry, overwrite: bool = False):
        """Register ``entry`` under ``name`` and return it.

        Parameters
        ----------
        name : str
            Non-empty name.
        entry : object
            What is registered.
        overwrite : bool, optional
            Replace an entry registered earlier under ``name`` (built-in ones cannot be replaced).

        Returns
        -------
        object
            ``entry``.

        Raises
        ------
        ValueError
            Empty name, a built-in name, or a taken name without ``overwrite``.
        TypeError
            ``entry`` does not meet the contract.
        """
        check_name(self.func, name)
        if self.protocol is not None:
            check_conforms(self.func, self.kind, name, entry, self.protocol)
        if name in self._builtin:
            raise ValueError(f"{self.func}: '{name}' is a built-in {self.kind}; choose another name")
        if name in self._entries and not overwrite:
            raise ValueError(f"{self.func}: a {self.kind} named '{name}' exists (pass overwrite=True)")
        self._entries[name] = entry
        return entry

    def remove(self, name: str) -> None:
        """Remove the entry registered under ``name``.

        Parameters
        ----------
        name : str
            A name added after :meth:`seal`.

        Raises
        ------
        ValueError
            For a built-in name.
        KeyError
            If nothing has that name.
        """
        if name in self._builtin:
            raise ValueError(f"'{name}' is a built-in {self.kind} and cannot be removed")
        if name not in self._entries:
            raise KeyError(f"no {self.kind} named '{name}'")
        del self._entries[name]

    def get(self, name: str):
        """The entry registered under ``name``.

        Parameters
        ----------
        name : str
            A registered name.

        Returns
        -------
        object

        Raises
        ------
        Exception
            ``missing`` (``KeyError`` by default) for an unknown name, listing the registered ones.
        """
        try:
            return self._entries[name]
        except (KeyError, TypeError):
            raise self.missing(f"unknown {self.kind} {name!r}; choose from {self.names()}") from None

    def names(self) -> tuple[str, ...]:
        """The registered names, in registration order.

        Returns
        -------
        tuple of str
        """
        return tuple(self._entries)

    def seal(self) -> None:
        """Make every name registered so far a built-in one."""
        self._builtin = frozenset(self._entries)

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
    expected : str or None, optional
        What ``obj`` should be, for the message (e.g. ``"a callable factory(seed) -> Layout"``);
        None accepts an object that is not callable.
    same_again : bool, optional
        Whether registering the very same object again under its name is accepted (default True;
        a registry whose registration has side effects, such as a Gymnasium id, passes False).
    protocol : type, optional
        The contract of :mod:`cogmap.genmodel.contracts` ``obj`` must meet
        (:func:`~cogmap.genmodel.contracts.check_conforms`).

    Raises
    ------
    TypeError
        ``obj`` is not callable (when ``expected`` is given), or does not meet ``protocol``.
    ValueError
        ``name`` is built in, or taken and ``overwrite`` is false.
    """
    if expected is not None and not callable(obj):
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
    when :meth:`seal` is called are built in (they can be neither replaced nor removed). An entry
    may declare the models it accepts (:meth:`accepting`).

    Every registry of the toolkit is one of these (inference schemes, planners, encoders, agents,
    studies); their module functions (``register_planner``, ``get_planner``, ...) are its methods.

    Parameters
    ----------
    kind : str
        What is registered (``"agent"``, ``"planner"``), for the messages.
    func : str
        The registering function's name, for the messages (``"register_agent"``).
    protocol : type, optional
        The contract of :mod:`cogmap.genmodel.contracts` every entry must meet.
    missing : type, optional
        The exception :meth:`get` raises for an unknown name, default ``KeyError``.
    expected : str, optional
        What an entry must be when it has to be callable (``"a callable factory(config) ->
        Encoder"``); None (the default) accepts any object.
    check : callable, optional
        ``check(name, entry)`` raising on a mistake of this kind the contract cannot see (run
        before the other checks).
    """

    def __init__(self, kind: str, func: str, protocol=None, missing: type[Exception] = KeyError,
                 expected: str | None = None, check: Callable[[str, object], None] | None = None):
        self.kind, self.func, self.protocol, self.missing, self.expected = kind, func, protocol, missing, expected
        self.check = check
        self._entries: dict = {}
        self._accepts: dict[str, Callable[[object], bool]] = {}
        self._builtin: frozenset[str] = frozenset()

    def add(self, name: str, entry, overwrite: bool = False, accepts=None):
        """Register ``entry`` under ``name`` and return it.

        Parameters
        ----------
        name : str
            Non-empty name.
        entry : object
            What is registered.
        overwrite : bool, optional
            Replace an entry registered earlier under ``name`` (built-in ones cannot be replaced;
            registering the very same entry again is always allowed).
        accepts : type, tuple of types or callable, optional
            The models the entry handles (:func:`accepts_test`); default every model.

        Returns
        -------
        object
            ``entry``.

        Raises
        ------
        ValueError
            Empty name, a built-in name, or a taken name without ``overwrite``.
        TypeError
            ``entry`` is not callable (when it must be), does not meet the contract, or
            ``accepts`` is none of the forms above.
        """
        check_name(self.func, name)
        test = accepts_test(f"{self.func}('{name}')", accepts)
        if self.check is not None:
            self.check(name, entry)
        check_entry(self.func, self.kind, name, entry, self._entries, self._builtin, overwrite,
                    expected=self.expected, protocol=self.protocol)
        self._entries[name] = entry
        self._accepts[name] = test
        return entry

    def register(self, name: str, entry=None, *, accepts=None, overwrite: bool = False):
        """Register ``entry`` under ``name``; without ``entry``, a decorator that registers its
        argument (``@register_planner("mine")``).

        Parameters
        ----------
        name : str
            Non-empty name.
        entry : object, optional
            What is registered; omit to get a decorator.
        accepts : type, tuple of types or callable, optional
            The models the entry handles (a model type, a tuple of them, or a test
            ``accepts(model) -> bool``); default every model.
        overwrite : bool, optional
            Replace an entry registered earlier under ``name`` (built-in ones cannot be replaced).

        Returns
        -------
        object
            ``entry``, or the decorator.

        Raises
        ------
        ValueError, TypeError
            As :meth:`add`.
        """
        check_name(self.func, name)
        accepts_test(f"{self.func}('{name}')", accepts)

        def _add(e):
            return self.add(name, e, overwrite, accepts)

        return _add if entry is None else _add(entry)

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
            If nothing has that name (the message lists the registered names).
        """
        if name in self._builtin:
            raise ValueError(f"'{name}' is a built-in {self.kind} and cannot be removed")
        if name not in self._entries:
            raise KeyError(f"no {self.kind} named '{name}' (available: {', '.join(self.available())})")
        del self._entries[name]
        self._accepts.pop(name, None)

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
            raise self.missing(f"unknown {self.kind} {name!r} (available: {', '.join(self.available())})") from None

    def names(self) -> tuple[str, ...]:
        """The registered names, in registration order.

        Returns
        -------
        tuple of str
        """
        return tuple(self._entries)

    def available(self) -> tuple[str, ...]:
        """The registered names, sorted.

        Returns
        -------
        tuple of str
        """
        return tuple(sorted(self._entries))

    def accepts(self, name: str, model) -> bool:
        """Whether the entry registered under ``name`` handles ``model`` (its ``accepts``).

        Parameters
        ----------
        name : str
            A registered name.
        model : object
            Any model.

        Returns
        -------
        bool

        Raises
        ------
        Exception
            ``missing`` for an unknown name.
        """
        self.get(name)
        return passes(self._accepts[name], model)

    def accepting(self, model) -> tuple[str, ...]:
        """The registered names (sorted) whose entries handle ``model``.

        Parameters
        ----------
        model : object
            Any model.

        Returns
        -------
        tuple of str
        """
        return tuple(n for n in self.available() if passes(self._accepts[n], model))

    def seal(self) -> None:
        """Make every name registered so far a built-in one."""
        self._builtin = frozenset(self._entries)

"""Typed schemas for saved state: every field is written and read by code that knows its type
and range; the file never names a class, a function or a module.

A schema is a tree of small field types (:class:`Int`, :class:`Float`, :class:`Array`,
:class:`ListOf`, :class:`Record`, ...). :func:`encode` turns a value into plain JSON nodes plus
a dictionary of arrays; :func:`decode` reads them back with the same schema, checking at every
position that the node has the declared type, that numbers are in range and finite where the
schema says so, that arrays have the declared dtype kind and number of dimensions, and that
records have exactly their declared fields. What gets built is decided by the schema (code), not
by the file. Objects met twice on writing (an agent's configuration shared with its view map, a
generator shared by the simulator and its odometry) are written once and referred to by number;
on reading a reference must point to an object already read of the type its position declares.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from typing import Any

import numpy as np

#: longest string a schema reads
MAX_STR = 10_000


class SchemaError(ValueError):
    """A value that does not fit its schema, naming where it sits."""


class Writer:
    """Encoding context: the arrays written so far and the objects already met."""

    def __init__(self):
        self.arrays: dict[str, np.ndarray] = {}
        self.memo: dict[int, int] = {}
        self.keep: list = []  # keeps encoded objects alive so their ids stay unique
        self.extra: dict[str, Any] = {}  # per-field-type context (e.g. the directory models go to)


class Reader:
    """Decoding context: the arrays of the file and the objects already read, by number.

    Parameters
    ----------
    arrays
        The arrays of the file, by the names the JSON nodes refer to.
    **extra
        Per-field-type context (e.g. the directory a model file is read from).
    """

    def __init__(self, arrays: dict[str, np.ndarray], **extra):
        self.arrays = arrays
        self.memo: dict[int, Any] = {}
        self.extra = extra


class Field:
    """A field type: :meth:`write` a value to a JSON node, :meth:`read` a node back."""

    #: Python type(s) a decoded value has (checked when a reference points here)
    pytype: type | tuple = object
    #: values of this type are objects that may be shared (written once, referred to after)
    shared = False

    def write(self, value, w: Writer, where: str):
        """``value`` as a JSON node (called by :func:`encode`).

        Parameters
        ----------
        value
            The value to write; refused unless it has this field's type and range.
        w
            The encoding context (arrays go to ``w.arrays``).
        where
            The value's position in the saved state, for error messages.

        Returns
        -------
        object
            A plain JSON node.

        Raises
        ------
        SchemaError
            When ``value`` does not fit the field, naming ``where``.
        """
        raise NotImplementedError

    def read(self, node, r: Reader, where: str):
        """The value of the JSON node ``node`` (called by :func:`decode`).

        Parameters
        ----------
        node
            A node of the parsed JSON file.
        r
            The decoding context (the file's arrays and the objects read so far).
        where
            The node's position in the saved state, for error messages.

        Returns
        -------
        object
            The value, of this field's type and range.

        Raises
        ------
        SchemaError
            When the node does not fit the field, naming ``where``.
        """
        raise NotImplementedError


def encode(schema: Field, value, w: Writer, where: str):
    """``value`` as a JSON node of ``schema`` (arrays go to ``w.arrays``).

    Parameters
    ----------
    schema
        The field type of ``value``.
    value
        The value to write.
    w
        The encoding context; an object met before (a shared field) is written as a reference.
    where
        The value's position, for error messages (e.g. ``"state"``).

    Returns
    -------
    object
        A plain JSON node.
    """
    if schema.shared and value is not None:
        key = id(value)
        if key in w.memo:
            return {"$ref": w.memo[key]}
        n = w.memo[key] = len(w.memo)
        w.keep.append(value)
        return {"$id": n, "v": schema.write(value, w, where)}
    return schema.write(value, w, where)


def decode(schema: Field, node, r: Reader, where: str):
    """The value of ``node`` read with ``schema``.

    Parameters
    ----------
    schema
        The field type declared at this position.
    node
        A node of the parsed JSON file.
    r
        The decoding context; a reference must point to an object already read, of ``schema``'s type.
    where
        The node's position, for error messages.

    Returns
    -------
    object
        The value built by ``schema`` (never by the file).

    Raises
    ------
    SchemaError
        When the node does not fit ``schema``, naming ``where``.
    """
    if schema.shared and isinstance(node, dict) and node.keys() == {"$ref"}:
        n = node["$ref"]
        if type(n) is not int or n not in r.memo:
            raise SchemaError(f"{where}: reference to an object not read before")
        obj = r.memo[n]
        if not isinstance(obj, schema.pytype):
            raise SchemaError(f"{where}: reference to a {type(obj).__name__}, expected {_names(schema.pytype)}")
        return obj
    if schema.shared and isinstance(node, dict) and node.keys() == {"$id", "v"}:
        n = node["$id"]
        if type(n) is not int or n in r.memo:
            raise SchemaError(f"{where}: bad or repeated object number")
        return schema.read(node["v"], r, where, n) if isinstance(schema, Record) else _memo(
            r, n, schema.read(node["v"], r, where))
    return schema.read(node, r, where)


def _memo(r: Reader, n: int, obj):
    r.memo[n] = obj
    return obj


def _names(t) -> str:
    return " or ".join(x.__name__ for x in (t if isinstance(t, tuple) else (t,)))


def _expect(node, types, where, what):
    if not isinstance(node, types) or (isinstance(node, bool) and bool not in _as_tuple(types)):
        raise SchemaError(f"{where}: expected {what}, got {_describe(node)}")


def _as_tuple(t):
    return t if isinstance(t, tuple) else (t,)


def _describe(node) -> str:
    if node is None:
        return "null"
    if isinstance(node, bool):
        return f"boolean {node}"
    if isinstance(node, int | float):
        return f"number {node!r}"
    if isinstance(node, str):
        return f"string {node[:40]!r}"
    return type(node).__name__ if not isinstance(node, dict) else f"object with keys {sorted(node)[:6]}"


class Bool(Field):
    """A boolean (``true`` / ``false``; numbers are refused)."""

    pytype = bool

    def write(self, value, w, where):
        if not isinstance(value, bool | np.bool_):
            raise SchemaError(f"{where}: expected a boolean, got {type(value).__name__}")
        return bool(value)

    def read(self, node, r, where):
        _expect(node, bool, where, "a boolean")
        return node


class Int(Field):
    """An integer in ``[lo, hi]`` (booleans and floats are refused).

    Parameters
    ----------
    lo, hi
        The inclusive bounds; None for no bound.
    """

    pytype = int

    def __init__(self, lo: int | None = None, hi: int | None = None):
        self.lo, self.hi = lo, hi

    def _check(self, v, where):
        if (self.lo is not None and v < self.lo) or (self.hi is not None and v > self.hi):
            raise SchemaError(f"{where}: {v} is outside [{self.lo}, {self.hi}]")
        return v

    def write(self, value, w, where):
        if isinstance(value, bool | np.bool_) or not isinstance(value, int | np.integer):
            raise SchemaError(f"{where}: expected an integer, got {type(value).__name__}")
        return self._check(int(value), where)

    def read(self, node, r, where):
        _expect(node, int, where, "an integer")
        return self._check(node, where)


class Float(Field):
    """A float in ``[lo, hi]``; NaN and infinities only when ``finite=False``.

    Parameters
    ----------
    lo, hi
        The inclusive bounds of a finite value; None for no bound.
    finite
        Whether NaN and infinities are refused.
    """

    pytype = float

    def __init__(self, lo: float | None = None, hi: float | None = None, finite: bool = True):
        self.lo, self.hi, self.finite = lo, hi, finite

    def _check(self, v, where):
        if math.isnan(v) or math.isinf(v):
            if self.finite:
                raise SchemaError(f"{where}: {v} is not a finite number")
            return v
        if (self.lo is not None and v < self.lo) or (self.hi is not None and v > self.hi):
            raise SchemaError(f"{where}: {v} is outside [{self.lo}, {self.hi}]")
        return v

    def write(self, value, w, where):
        if isinstance(value, bool | np.bool_) or not isinstance(value, int | float | np.integer | np.floating):
            raise SchemaError(f"{where}: expected a number, got {type(value).__name__}")
        return self._check(float(value), where)

    def read(self, node, r, where):
        _expect(node, int | float, where, "a number")
        return self._check(float(node), where)


class Str(Field):
    """A string, one of ``choices`` when given.

    Parameters
    ----------
    choices
        The strings allowed; None for any.
    max_len
        The longest string read.
    """

    pytype = str

    def __init__(self, choices: tuple[str, ...] | None = None, max_len: int = MAX_STR):
        self.choices, self.max_len = choices, max_len

    def _check(self, v, where):
        if len(v) > self.max_len:
            raise SchemaError(f"{where}: string longer than {self.max_len} characters")
        if self.choices is not None and v not in self.choices:
            raise SchemaError(f"{where}: {v[:40]!r} is not one of {', '.join(map(repr, self.choices))}")
        return v

    def write(self, value, w, where):
        if not isinstance(value, str):
            raise SchemaError(f"{where}: expected a string, got {type(value).__name__}")
        return self._check(value, where)

    def read(self, node, r, where):
        _expect(node, str, where, "a string")
        return self._check(node, where)


class Optional(Field):
    """``None`` or a value of ``inner``.

    Parameters
    ----------
    inner
        The field type of a value that is not None.
    """

    def __init__(self, inner: Field):
        self.inner = inner
        self.pytype = (*_as_tuple(inner.pytype), type(None))

    def write(self, value, w, where):
        return None if value is None else encode(self.inner, value, w, where)

    def read(self, node, r, where):
        return None if node is None else decode(self.inner, node, r, where)


class OneOf(Field):
    """A value of the first of ``options`` whose Python type it has (written as ``[index, node]``).

    Parameters
    ----------
    *options
        The field types a value may have.
    """

    def __init__(self, *options: Field):
        self.options = options
        self.pytype = tuple(t for o in options for t in _as_tuple(o.pytype))

    def write(self, value, w, where):
        for i, o in enumerate(self.options):
            if isinstance(value, o.pytype) and not (isinstance(value, bool) and o.pytype in (int, float)):
                return [i, encode(o, value, w, where)]
        raise SchemaError(f"{where}: {type(value).__name__} is none of {_names(self.pytype)}")

    def read(self, node, r, where):
        if not (isinstance(node, list) and len(node) == 2 and type(node[0]) is int
                and 0 <= node[0] < len(self.options)):
            raise SchemaError(f"{where}: expected [option, value], got {_describe(node)}")
        return decode(self.options[node[0]], node[1], r, where)


class Array(Field):
    """A numpy array of a dtype kind in ``kinds`` (``numpy.dtype.kind`` letters) with ``ndim``
    dimensions (any when None) and, where given, the fixed sizes of ``shape`` (None: any).

    Parameters
    ----------
    kinds
        The dtype kinds allowed (``"f"`` float, ``"i"``/``"u"`` integer, ``"b"`` boolean).
    ndim
        The number of dimensions; None for any.
    shape
        The size of each dimension (None entries: any); None for any shape.
    finite
        Whether NaN and infinities are refused in float arrays.
    """

    pytype = np.ndarray
    shared = True

    def __init__(self, kinds: str = "f", ndim: int | None = None, shape: tuple | None = None,
                 finite: bool = False):
        self.kinds, self.ndim, self.shape, self.finite = kinds, ndim, shape, finite

    def _check(self, a, where):
        if a.dtype.kind not in self.kinds:
            raise SchemaError(f"{where}: array of dtype {a.dtype}, expected kind(s) {self.kinds!r}")
        if self.ndim is not None and a.ndim != self.ndim:
            raise SchemaError(f"{where}: array of {a.ndim} dimension(s), expected {self.ndim}")
        if self.shape is not None and any(s is not None and s != n for s, n in zip(self.shape, a.shape, strict=True)):
            raise SchemaError(f"{where}: array of shape {a.shape}, expected {self.shape}")
        if self.finite and a.dtype.kind == "f" and not np.isfinite(a).all():
            raise SchemaError(f"{where}: array holds NaN or infinite values")
        return a

    def write(self, value, w, where):
        if not isinstance(value, np.ndarray):
            raise SchemaError(f"{where}: expected an array, got {type(value).__name__}")
        self._check(value, where)
        key = f"a{len(w.arrays)}"
        w.arrays[key] = value
        return key

    def read(self, node, r, where):
        _expect(node, str, where, "an array name")
        if node not in r.arrays:
            raise SchemaError(f"{where}: array {node[:40]!r} is missing from the archive")
        return self._check(np.array(r.arrays[node]), where)


class ListOf(Field):
    """A list whose items all have one field type.

    Parameters
    ----------
    item
        The field type of every item.
    """

    pytype = list
    shared = True

    def __init__(self, item: Field):
        self.item = item

    def write(self, value, w, where):
        if not isinstance(value, list):
            raise SchemaError(f"{where}: expected a list, got {type(value).__name__}")
        return [encode(self.item, v, w, f"{where}[{i}]") for i, v in enumerate(value)]

    def read(self, node, r, where):
        _expect(node, list, where, "a list")
        return [decode(self.item, v, r, f"{where}[{i}]") for i, v in enumerate(node)]


class SetOf(ListOf):
    """A set whose items all have one (hashable) field type, written as a sorted list.

    Parameters
    ----------
    item
        The field type of every item.
    """

    pytype = set

    def write(self, value, w, where):
        if not isinstance(value, set):
            raise SchemaError(f"{where}: expected a set, got {type(value).__name__}")
        return [encode(self.item, v, w, f"{where}{{}}") for v in value]

    def read(self, node, r, where):
        _expect(node, list, where, "a list of set members")
        return {decode(self.item, v, r, f"{where}{{}}") for v in node}


class TupleOf(Field):
    """A tuple of fixed length with one field type per position.

    Parameters
    ----------
    *items
        The field type of each position.
    """

    pytype = tuple

    def __init__(self, *items: Field):
        self.items = items

    def write(self, value, w, where):
        if not isinstance(value, tuple) or len(value) != len(self.items):
            raise SchemaError(f"{where}: expected a tuple of {len(self.items)}, got {type(value).__name__}")
        return [encode(s, v, w, f"{where}[{i}]") for i, (s, v) in enumerate(zip(self.items, value, strict=True))]

    def read(self, node, r, where):
        if not isinstance(node, list) or len(node) != len(self.items):
            raise SchemaError(f"{where}: expected a list of {len(self.items)}, got {_describe(node)}")
        return tuple(decode(s, v, r, f"{where}[{i}]") for i, (s, v) in enumerate(zip(self.items, node, strict=True)))


class VarTuple(ListOf):
    """A tuple of any length whose items all have one field type.

    Parameters
    ----------
    item
        The field type of every item.
    """

    pytype = tuple
    shared = False

    def write(self, value, w, where):
        if not isinstance(value, tuple):
            raise SchemaError(f"{where}: expected a tuple, got {type(value).__name__}")
        return [encode(self.item, v, w, f"{where}[{i}]") for i, v in enumerate(value)]

    def read(self, node, r, where):
        return tuple(super().read(node, r, where))


class DictOf(Field):
    """A dict with keys of one field type and values of another (written as a list of pairs).

    Parameters
    ----------
    key, value
        The field types of the keys and of the values.
    """

    pytype = dict
    shared = True

    def __init__(self, key: Field, value: Field):
        self.key, self.value = key, value

    def write(self, value, w, where):
        if not isinstance(value, dict):
            raise SchemaError(f"{where}: expected a dict, got {type(value).__name__}")
        return [[encode(self.key, k, w, f"{where} key"), encode(self.value, v, w, f"{where}[{k!r}]")]
                for k, v in value.items()]

    def read(self, node, r, where):
        _expect(node, list, where, "a list of [key, value] pairs")
        out = {}
        for i, pair in enumerate(node):
            if not (isinstance(pair, list) and len(pair) == 2):
                raise SchemaError(f"{where}[{i}]: expected a [key, value] pair")
            k = decode(self.key, pair[0], r, f"{where} key")
            out[k] = decode(self.value, pair[1], r, f"{where}[{k!r}]")
        return out


class Record(Field):
    """An instance of ``cls`` with exactly the fields ``fields`` (name to field type).

    ``make`` builds it: ``"new"`` (default) creates the instance without calling ``__init__`` and
    sets the fields (plain classes and dataclasses, frozen ones included); ``"call"`` calls
    ``cls(**fields)`` (named tuples and dataclasses whose constructor checks its arguments).
    ``drop`` lists attributes that are not written and are read back as the given constants
    (diagnostic caches, for instance).

    Parameters
    ----------
    cls
        The exact class of the value (a subclass is refused).
    fields
        Each attribute's name and field type; the value must have exactly these.
    make
        How the instance is built on reading, ``"new"`` or ``"call"``.
    drop
        Attributes not written, each read back as the result of its function.
    """

    shared = True

    def __init__(self, cls: type, fields: dict[str, Field], make: str = "new",
                 drop: dict[str, Callable[[], Any]] | None = None):
        self.cls, self.pytype, self.fields, self.make = cls, cls, fields, make
        self.drop = drop or {}

    def _values(self, value) -> dict:
        if hasattr(value, "_fields"):
            return dict(zip(value._fields, value, strict=True))
        out = {f.name: getattr(value, f.name) for f in dataclasses.fields(value)} if dataclasses.is_dataclass(
            value) else {}
        out.update(getattr(value, "__dict__", {}))
        return out

    def write(self, value, w, where):
        if type(value) is not self.cls:
            raise SchemaError(f"{where}: {type(value).__module__}.{type(value).__qualname__} has no checkpoint "
                              f"schema (expected {self.cls.__qualname__})")
        values = {k: v for k, v in self._values(value).items() if k not in self.drop}
        if values.keys() != self.fields.keys():
            extra, missing = sorted(values.keys() - self.fields.keys()), sorted(self.fields.keys() - values.keys())
            raise SchemaError(f"{where}: {self.cls.__qualname__}'s fields differ from its schema (not in the schema: "
                              f"{extra}; missing: {missing})")
        return {k: encode(s, values[k], w, f"{where}.{k}") for k, s in self.fields.items()}

    def read(self, node, r, where, n: int | None = None):
        _expect(node, dict, where, f"the fields of {self.cls.__qualname__}")
        if node.keys() != self.fields.keys():
            extra, missing = sorted(node.keys() - self.fields.keys()), sorted(self.fields.keys() - node.keys())
            raise SchemaError(f"{where}: {self.cls.__qualname__} with unknown field(s) {extra[:5]} or missing "
                              f"field(s) {missing[:5]}")
        if self.make == "call":
            values = {k: decode(s, node[k], r, f"{where}.{k}") for k, s in self.fields.items()}
            try:
                obj = self.cls(**values)
            except (TypeError, ValueError) as err:
                raise SchemaError(f"{where}: {err}") from None
            return obj if n is None else _memo(r, n, obj)
        obj = self.cls.__new__(self.cls)
        if n is not None:
            r.memo[n] = obj  # before the fields, so they may refer back to it
        for k, s in self.fields.items():
            object.__setattr__(obj, k, decode(s, node[k], r, f"{where}.{k}"))
        for k, make in self.drop.items():
            object.__setattr__(obj, k, make())
        return obj


class Via(Field):
    """A value written as another schema's value through two functions (e.g. a configuration as
    its validated ``to_dict`` / ``from_dict``).

    Parameters
    ----------
    pytype
        The type of the value.
    inner
        The field type of what ``to`` returns.
    to, back
        Value to ``inner``'s value, and back (``back`` validates; its errors become :class:`SchemaError`).
    """

    shared = True

    def __init__(self, pytype: type, inner: Field, to: Callable, back: Callable):
        self.pytype, self.inner, self.to, self.back = pytype, inner, to, back

    def write(self, value, w, where):
        if not isinstance(value, self.pytype):
            raise SchemaError(f"{where}: expected a {self.pytype.__name__}, got {type(value).__name__}")
        return encode(self.inner, self.to(value), w, where)

    def read(self, node, r, where):
        try:
            return self.back(decode(self.inner, node, r, where))
        except SchemaError:
            raise
        except (TypeError, ValueError, KeyError) as err:
            raise SchemaError(f"{where}: {err}") from None


class Json(Field):
    """A plain JSON value (null, booleans, finite numbers, strings, lists and string-keyed objects) of
    bounded depth, for free-form records such as configuration dictionaries.

    Parameters
    ----------
    max_depth
        The deepest nesting read.
    """

    pytype = (dict, list, str, int, float, bool, type(None))

    def __init__(self, max_depth: int = 8):
        self.max_depth = max_depth

    def _check(self, v, where, depth=0):
        if depth > self.max_depth:
            raise SchemaError(f"{where}: nested deeper than {self.max_depth}")
        if v is None or isinstance(v, bool | int | str):
            return v
        if isinstance(v, float):
            if not math.isfinite(v):
                raise SchemaError(f"{where}: {v} is not a finite number")
            return v
        if isinstance(v, list | tuple):  # a tuple is written as a list
            return [self._check(x, f"{where}[{i}]", depth + 1) for i, x in enumerate(v)]
        if isinstance(v, dict) and all(isinstance(k, str) for k in v):
            return {k: self._check(x, f"{where}.{k}", depth + 1) for k, x in v.items()}
        raise SchemaError(f"{where}: {type(v).__name__} is not a plain JSON value")

    def write(self, value, w, where):
        return self._check(value, where)

    def read(self, node, r, where):
        return self._check(node, where)


class Generator(Field):
    """A numpy generator, written as its bit generator's state; only the bit generators in
    :data:`BIT_GENERATORS` are rebuilt."""

    pytype = np.random.Generator
    shared = True
    BIT_GENERATORS = {"PCG64": np.random.PCG64, "PCG64DXSM": np.random.PCG64DXSM}
    _STATE = DictOf(Str(), OneOf(Int(), Str(), DictOf(Str(), Int())))

    def write(self, value, w, where):
        if not isinstance(value, np.random.Generator):
            raise SchemaError(f"{where}: expected a numpy Generator, got {type(value).__name__}")
        state = value.bit_generator.state
        if state.get("bit_generator") not in self.BIT_GENERATORS:
            raise SchemaError(f"{where}: bit generator {state.get('bit_generator')} cannot be checkpointed "
                              f"(only {', '.join(self.BIT_GENERATORS)})")
        return self._STATE.write(state, w, where)

    def read(self, node, r, where):
        state = self._STATE.read(node, r, where)
        cls = self.BIT_GENERATORS.get(state.get("bit_generator"))
        if cls is None:
            raise SchemaError(f"{where}: bit generator {str(state.get('bit_generator'))[:40]!r} is not one of "
                              f"{', '.join(self.BIT_GENERATORS)}")
        bit = cls()
        try:
            bit.state = state
        except (TypeError, ValueError, KeyError, OverflowError) as err:
            raise SchemaError(f"{where}: bad generator state ({err})") from None
        return np.random.Generator(bit)

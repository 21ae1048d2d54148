"""Argument types of the command line: bounded integers and finite numbers, refused in one line.

Every numeric flag of every ``cogmap`` command is parsed by one of these, so a value out of its
range (negative, non-finite, above a documented limit) ends the command at parse time with
``cogmap CMD: error: argument --FLAG: ...`` and exit status 2, before anything runs.
"""

from __future__ import annotations

import argparse
import math

#: largest seed a flag takes: seeds reach numpy, pybullet and jax (``jax.random.PRNGKey``), whose
#: common range is a signed 32-bit integer
MAX_SEED = 2**31 - 1
#: largest number of decisions of one AIMAPP run (``cogmap explore --steps``, ``cogmap goal --steps``,
#: ``steps`` in an exploration's run.json); the studies use at most 300
MAX_DECISIONS = 100_000
#: largest number of drone episodes (``cogmap drone fly --episodes``, ``--first-episode``, ``--pictures``)
MAX_EPISODES = 100_000
#: largest number of time steps of a DVBF-LM run (``cogmap dvbf slam|explore --steps``): ten times
#: the largest exploration budget of Table II (18,000)
MAX_DVBF_STEPS = 200_000
#: largest ``cogmap dvbf navigate --pairs``: every ordered pair of the 5 x 5 pose grid (25 x 24)
MAX_PAIRS = 600


def bounded_int(minimum: int, maximum: int | None = None, name: str | None = None):
    """An argparse type: an integer in ``minimum .. maximum`` (``maximum`` None: no upper bound).

    Parameters
    ----------
    minimum : int
        Smallest accepted value.
    maximum : int or None, optional
        Largest accepted value; name its constant in ``name`` so the message says which limit it is.
    name : str or None, optional
        Name of the limit (e.g. ``"MAX_STEPS"``), quoted in the refusal.

    Returns
    -------
    callable
        ``parse(text) -> int``, raising ``argparse.ArgumentTypeError``.
    """
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected an integer, got {text!r}") from None
        if value < minimum:
            raise argparse.ArgumentTypeError(f"must be at least {minimum}, got {value}")
        if maximum is not None and value > maximum:
            limit = f" ({name})" if name else ""
            raise argparse.ArgumentTypeError(f"must be at most {maximum}{limit}, got {value}")
        return value

    parse.__name__ = f"integer >= {minimum}" if maximum is None else f"integer in {minimum}..{maximum}"
    return parse


def bounded_float(minimum: float | None = None, maximum: float | None = None, name: str | None = None,
                  open_minimum: bool = False):
    """An argparse type: a finite number in ``[minimum, maximum]`` (``open_minimum``: above ``minimum``).

    Parameters
    ----------
    minimum, maximum : float or None, optional
        Bounds (None: none on that side; the number must still be finite).
    name : str or None, optional
        Name of the limit constant, quoted in the refusal.
    open_minimum : bool, optional
        Refuse ``minimum`` itself (a positive number: ``minimum=0, open_minimum=True``).

    Returns
    -------
    callable
        ``parse(text) -> float``, raising ``argparse.ArgumentTypeError``.
    """
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
        if not math.isfinite(value):
            raise argparse.ArgumentTypeError(f"must be a finite number, got {text}")
        low = minimum is not None and (value <= minimum if open_minimum else value < minimum)
        high = maximum is not None and value > maximum
        if low or high:
            lo = "" if minimum is None else (f"> {minimum:g}" if open_minimum else f">= {minimum:g}")
            hi = "" if maximum is None else f"<= {maximum:g}"
            limit = f" ({name})" if name else ""
            raise argparse.ArgumentTypeError(f"must be {' and '.join(x for x in (lo, hi) if x)}{limit}, got {text}")
        return value

    parse.__name__ = "number"
    return parse


positive_int = bounded_int(1)
nonnegative_int = bounded_int(0)
#: a seed: an integer in 0 .. MAX_SEED
seed_int = bounded_int(0, MAX_SEED, "MAX_SEED")
seed_int.__name__ = "seed"


def positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not value > 0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"must be a positive finite number, got {text}")
    return value


positive_float.__name__ = "positive number"


def nonnegative_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not value >= 0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"must be a finite number >= 0, got {text}")
    return value


nonnegative_float.__name__ = "number >= 0"


class OneLineParser(argparse.ArgumentParser):
    """An ``ArgumentParser`` whose errors are one line on stderr (``prog: error: ...``), exit 2."""

    def error(self, message: str):  # noqa: D401 - argparse API
        self.exit(2, f"{self.prog}: error: {' '.join(message.split())}\n")


def one_line(err: BaseException) -> str:
    """An error as one line: its message (its type too when the message alone is unclear)."""
    text = " ".join(str(err).split())
    if isinstance(err, OSError) and err.filename is not None and err.strerror:
        return f"{err.filename}: {err.strerror}"
    if isinstance(err, ValueError | RuntimeError | OSError) and text:
        return text
    return f"{type(err).__name__}: {text}" if text else type(err).__name__
